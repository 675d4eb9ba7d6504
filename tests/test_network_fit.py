"""Calibration of a network (``Network.fit``, ``docs/network.md``, "Calibration").

References: synthetic data from known parameters (recovered to 1e-8); a linear case, a chain of
rigid Newtonian tubes fed a known inflow and ending in a resistance outlet, whose node pressures
are linear in the resistance, against ordinary least squares in closed form (estimate and
standard error); and, for compliant tubes with noisy data, the standard errors against the
Gauss–Newton covariance of a Jacobian by central differences of independent network solves.
"""

from __future__ import annotations

import math
import pathlib
import re
import warnings

import numpy as np
import pytest

import tubefsi
from tubefsi import InvalidParameterError, Network, Tube
from tubefsi.registry import rheologies, walls

FLUID = rheologies["power-law"](consistency=0.01, index=0.7)
GROUPS = {"proximal": [("in", "j"), "x"], "distal": [("j", "a"), ("j", "b")]}


def _tube(a):
    return Tube(radius=a, thickness=0.3 * a, length=1e-2)


def diamond(mu_proximal, mu_distal, resistance):
    """An inflow into a Y whose branches are joined by a cross tube "x"; one branch ends at a fixed
    pressure, the other at a resistance outlet."""
    wall = lambda mu: walls["thick-neo-hookean"](shear_modulus=mu)   # noqa: E731
    net = Network(rheology=FLUID)
    net.add_tube("in", "j", wall(mu_proximal), _tube(1.2e-4))
    net.add_tube("j", "a", wall(mu_distal), _tube(1e-4))
    net.add_tube("j", "b", wall(mu_distal), _tube(0.9e-4))
    net.add_tube("a", "b", wall(mu_proximal), _tube(0.8e-4), name="x")
    net.set_inflow("in", 2e-9).set_pressure("a", 100.0).set_resistance("b", resistance, distal_pressure=50.0)
    return net


def _measure(result):
    return ({n: result.pressure[n] for n in ("in", "j", "b")},
            {"x": result.flow_rate["x"], ("j", "a"): result.flow_rate[("j", "a")]})


def test_synthetic_data_recover_the_parameters():
    """Two modulus groups and a terminal resistance from three pressures and two flows of the
    network at known values, starting 25-50 % off: recovered to 1e-8."""
    pressure, flow = _measure(diamond(4e3, 8e3, 3e12).solve())
    fitted = diamond(5e3, 6e3, 2e12).fit(pressure=pressure, flow_rate=flow, moduli=GROUPS, resistances=["b"])
    assert fitted.success
    for name, truth in (("modulus[proximal]", 4e3), ("modulus[distal]", 8e3), ("resistance[b]", 3e12)):
        assert fitted.parameters[name] == pytest.approx(truth, rel=1e-8)
    assert fitted.network._resistance["b"][0] == pytest.approx(3e12, rel=1e-8)
    assert fitted.solution.pressure["j"] == pytest.approx(pressure["j"], rel=1e-10)
    assert "modulus[distal]" in str(fitted)


def test_a_linear_case_against_ordinary_least_squares():
    """Rigid Newtonian tubes in -> a -> b -> o, inflow Q, outlet resistance R to p_d: the node
    pressures p_i = p_d + Q (R + sum of the Poiseuille resistances downstream) are linear in R, so
    the fitted R and its standard error are those of ordinary least squares in closed form,
    R = sum(b (y - c)) / sum(b^2), se = sqrt(s^2 / sum(b^2)), b = Q / sigma (here to 1e-9)."""
    mu, q, p_d, sigma = 1e-3, 1e-9, 20.0, 2.0
    radii = {("in", "a"): 1e-4, ("a", "b"): 0.9e-4, ("b", "o"): 1.1e-4}
    poiseuille = {e: 8 * mu * 1e-2 / (math.pi * a**4) for e, a in radii.items()}

    def chain(r):
        net = Network(rheology=rheologies["newtonian"](viscosity=mu))
        for (u, v), a in radii.items():
            net.add_tube(u, v, walls["rigid"](), _tube(a))
        return net.set_inflow("in", q).set_resistance("o", r, distal_pressure=p_d)

    downstream = {"in": sum(poiseuille.values()), "a": poiseuille[("a", "b")] + poiseuille[("b", "o")],
                  "b": poiseuille[("b", "o")], "o": 0.0}
    noise = {"in": 1.5, "a": -2.0, "b": 0.7, "o": 1.1}
    truth = 4e10
    measured = {n: p_d + q * (truth + downstream[n]) + noise[n] for n in downstream}
    fitted = chain(1e10).fit(pressure=measured, resistances=["o"], pressure_sigma=sigma)
    y = np.array([measured[n] - p_d - q * downstream[n] for n in downstream]) / sigma
    b = np.full(4, q / sigma)
    r_hat = float(b @ y / (b @ b))
    s2 = float(np.sum((y - b * r_hat) ** 2)) / (4 - 1)
    assert fitted.parameters["resistance[o]"] == pytest.approx(r_hat, rel=1e-9)
    assert fitted.standard_errors["resistance[o]"] == pytest.approx(math.sqrt(s2 / (b @ b)), rel=1e-9)


def test_standard_errors_against_a_finite_difference_jacobian():
    """Noisy data (a fixed draw, 1 % of each value): the standard errors equal the Gauss–Newton
    ones from a Jacobian by central differences (log steps 1e-5) of network solves at the
    fitted values, independent of the implicit-function Jacobian: 1e-5."""
    rng = np.random.default_rng(7)
    pressure, flow = _measure(diamond(4e3, 8e3, 3e12).solve())
    pressure = {n: v * (1 + 0.01 * rng.standard_normal()) for n, v in pressure.items()}
    flow = {n: v * (1 + 0.01 * rng.standard_normal()) for n, v in flow.items()}
    fitted = diamond(4e3, 8e3, 3e12).fit(pressure=pressure, flow_rate=flow, moduli=GROUPS, resistances=["b"])
    values = [fitted.parameters[k] for k in ("modulus[proximal]", "modulus[distal]", "resistance[b]")]
    sp_ = math.sqrt(np.mean(np.array(list(pressure.values())) ** 2))
    sq = math.sqrt(np.mean(np.array(list(flow.values())) ** 2))

    def observed(theta):
        r = diamond(*np.exp(theta)).solve()
        p, f = _measure(r)
        return np.array([p[n] / sp_ for n in pressure] + [f[n] / sq for n in flow])

    theta = np.log(values)
    h = 1e-5
    jac = np.column_stack([(observed(theta + h * e) - observed(theta - h * e)) / (2 * h) for e in np.eye(3)])
    s2 = float(np.sum(fitted.residuals**2)) / (5 - 3)
    cov = s2 * np.linalg.inv(jac.T @ jac) * np.outer(values, values)
    for i, name in enumerate(("modulus[proximal]", "modulus[distal]", "resistance[b]")):
        assert fitted.standard_errors[name] == pytest.approx(math.sqrt(cov[i, i]), rel=1e-5)


def test_fit_input_errors():
    net = diamond(4e3, 8e3, 3e12)
    data = dict(pressure={"in": 600.0, "j": 480.0, "b": 300.0})
    with pytest.raises(InvalidParameterError, match="tube names"):
        net.fit(moduli={"g": ["nope"]}, **data)
    with pytest.raises(InvalidParameterError, match="one value"):
        net.fit(moduli={"g": [("in", "j"), ("j", "a")]}, **data)
    with pytest.raises(InvalidParameterError, match="each"):
        net.fit(moduli={"g": [("in", "j")], "h": [("in", "j")]}, **data)
    with pytest.raises(InvalidParameterError, match="resistance outlet"):
        net.fit(resistances=["a"], **data)
    with pytest.raises(InvalidParameterError, match="more measurements"):
        net.fit(pressure={"in": 600.0}, resistances=["b"], moduli={"g": ["x"]})
    with pytest.raises(InvalidParameterError, match="at least one parameter"):
        net.fit(**data)
    with pytest.raises(InvalidParameterError, match="nodes of the network"):
        net.fit(pressure={"zz": 1.0, "in": 2.0}, resistances=["b"])
    rigid = Network(rheology=FLUID).add_tube("a", "b", walls["rigid"](), _tube(1e-4)).set_pressure("a", 1.0)
    with pytest.raises(InvalidParameterError, match="compliant"):
        rigid.fit(pressure={"a": 1.0, "b": 0.0}, moduli={"g": [("a", "b")]})


def test_unsupported_data_warn():
    """A modulus that the data do not determine (the tube's flow is the inflow and only the
    fixed node's pressure is measured: the Jacobian's column is zero): FitWarning, as tubefsi.fit."""
    net = Network(rheology=FLUID)
    net.add_tube("a", "b", walls["thick-neo-hookean"](shear_modulus=4e3), _tube(1e-4))
    net.set_inflow("a", 1e-9).set_pressure("b", 10.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        net.fit(flow_rate={("a", "b"): 1e-9}, pressure={"b": 10.0}, moduli={"g": [("a", "b")]})
    assert any(issubclass(w.category, tubefsi.FitWarning) and "not determined" in str(w.message) for w in caught)


def test_the_calibration_snippet_of_the_docs_runs_and_recovers_its_truth():
    """docs/network.md, "Calibration": its Python block runs (it once gave 3 measurements for 3
    parameters) and recovers the values its synthetic measurements were made with."""
    text = (pathlib.Path(__file__).parents[1] / "docs" / "network.md").read_text()
    section = text[text.index("## Calibration"):]
    block = re.search(r"```python\n(.*?)```", section, flags=re.S).group(1)
    namespace: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tubefsi.ModelValidityWarning)
        exec(compile(block.replace("print(fitted)", "str(fitted)"), "docs/network.md", "exec"), namespace)
    found = namespace["fitted"].parameters
    truth = {"modulus[arteries]": 30e3, "modulus[branches]": 10e3, "resistance[b]": 2e12}
    for name, value in truth.items():
        assert abs(found[name] / value - 1) < 1e-8, (name, found[name])
