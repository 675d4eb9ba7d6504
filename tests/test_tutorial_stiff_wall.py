"""The stiff-wall tutorial runs as written: docs/tutorials/wall-law-in-a-script.md, section 6.

Every ``python`` code block of that section is extracted and run, in order, in one namespace
standing for this module (as a reader would paste them into one file); the contract-suite
classes it defines (``TestFibreWall``, ``TestFibreAccuracy``) are then collected from here by
pytest, so the tutorial's law passes ``HyperelasticWallContract`` and ``AccuracyContract`` or
this file fails. The checks below pin what the text says of the bare and the guarded law.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
from pathlib import Path

import numpy as np
import pytest

import tubefsi

PAGE = Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "wall-law-in-a-script.md"


def _section_code(text, heading="## 6."):
    """The ``python`` blocks between the heading that starts with ``heading`` and the next ``## ``."""
    start = text.index("\n" + heading)
    end = text.find("\n## ", start + 1)
    section = text[start:end if end >= 0 else None]
    return re.findall(r"```python\n(.*?)```", section, flags=re.S)


BLOCKS = _section_code(PAGE.read_text(encoding="utf-8"))
_NS = {"__name__": __name__}
_OUT = io.StringIO()
with contextlib.redirect_stdout(_OUT):          # the tutorial prints; keep the test run quiet
    for _block in BLOCKS:
        exec(compile(_block, f"{PAGE.name} (section 6)", "exec"), _NS)

TestFibreWall = _NS["TestFibreWall"]
TestFibreAccuracy = _NS["TestFibreAccuracy"]


def test_the_section_has_its_code_blocks():
    assert len(BLOCKS) == 4                      # bare law, guarded law, use, suites


def test_the_guarded_law_is_the_issue_s_fibre_law_and_ends_where_the_text_says():
    """dW against the formula written out here; the maximum stretch where k2 (s^2 - 1)^2 = 600;
    the analytic d2W against a central difference of dW (well inside the range)."""
    wall = _NS["ThickFibre"](shear_modulus=1e3, k1=1e4, k2=20.0)
    s = np.array([1.0 + 1e-9, 1.1, 1.5, 2.0, 2.5])
    expected = 1e3 * (s**2 - 1) * (s**2 + 1) / s**3 + 2e4 * s * (s**2 - 1) * np.exp(20 * (s**2 - 1) ** 2)
    np.testing.assert_allclose(wall._dW(s), expected, rtol=1e-7)   # s^2 - 1 by subtraction: 1e-7 at 1 + 1e-9
    lam = wall.max_stretch(0.3)
    assert 20 * (lam**2 - 1) ** 2 == pytest.approx(600.0, rel=1e-12)
    h = 1e-6 * s[1:-1]
    central = (wall._dW(s[1:-1] + h) - wall._dW(s[1:-1] - h)) / (2 * h)
    np.testing.assert_allclose(wall._d2W(s[1:-1]), central, rtol=1e-6)
    assert math.isfinite(wall.limit_pressure(0.3))
    assert wall.limit_pressure(0.3) == pytest.approx(float(wall.pressure(lam * (1 - 1e-15), 0.3)), rel=1e-9)


def test_what_the_tutorial_prints():
    out = _OUT.getvalue()
    assert "finite double" in out                # the bare law's overflow, refused
    assert "limit pressure" in out               # NoSteadyStateError naming the limit
    assert "k2" in out                           # the field's own message for k2 = -1
    sol = tubefsi.solve(tubefsi.registry.rheologies["power-law"](consistency=0.01, index=0.8),
                        _NS["wall"], tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2), flow_rate=1e-8)
    assert sol.coupler_name == "quadrature" and 1.0 < sol.inlet_radius / 1e-4 < 1.2
