"""The fluid of the tutorial (docs/tutorials/wall-law-in-a-script.md, section 7) runs as written and
gives the Sisko law's tube flow. Reference: the Rabinowitsch–Mooney integral of the Sisko law taken
here independently (SciPy's quad over the stress, the shear rate by brentq), at 1e-10."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from scipy import integrate, optimize

PAGE = Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "wall-law-in-a-script.md"


def run_sections():
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(), flags=re.S)
    sisko = next(i for i, b in enumerate(blocks) if "class Sisko" in b)
    namespace: dict = {}
    for block in blocks[:4] + [blocks[sisko]]:    # imports, the wall (sections 1-3), the fluid
        exec(compile(block, str(PAGE), "exec"), namespace)
    return namespace


def sisko_flow_rate(eta, k, n, radius, gradient):
    tau_w = 0.5 * gradient * radius

    def rate(tau):
        return optimize.brentq(lambda g: eta * g + k * g**n - tau, 0.0, tau / eta, xtol=1e-300, rtol=1e-15)

    integral, _ = integrate.quad(lambda t: t * t * rate(t), 0.0, tau_w, epsabs=0, epsrel=1e-13, limit=200)
    return math.pi * radius**3 * integral / tau_w**3


def test_the_tutorials_fluid_runs_and_flows_as_the_sisko_law():
    ns = run_sections()
    blood, sol = ns["blood"], ns["sol"]
    assert sol.pressure_drop > 0
    radius, gradient = 1e-4, 2e3
    expected = sisko_flow_rate(0.0035, 0.017, 0.6, radius, gradient)
    assert np.isclose(blood.flow_rate(radius, gradient), expected, rtol=1e-10, atol=0)
