r"""Work–precision chart: relative error against time per point for every tubefsi method.

Run ``python examples/work_precision.py [OUTDIR]`` (default: the repository's ``docs/``); it writes
``OUTDIR/work_precision.png`` and prints a table (error, time per point, speed ratio against
the chapter's method). Headless (matplotlib Agg); about 70 s on two cores. ``--quick`` runs
every step at small sizes (3 reference points, 2 quadrature orders, one ODE method at one
tolerance, a tiny time budget: seconds; a smoke test, not the published chart).

Scenes (tube: a = 100 µm, t = 30 µm, L = 1 cm; power-law fluid m = 0.017 Pa s^n, n = 0.7)
--------------------------------------------------------------------------------------------
1. *thin closed form*: thin reference-thickness neo-Hookean wall (μ = 2 kPa), strains 0.01–3;
2. *thick Mooney–Rivlin, moderate load*: c1 = 1.5 kPa, c2 = −0.5 kPa, strains 0.02–1.5
   (up to 33 % of the maximum flow rate);
3. *thick Mooney–Rivlin, near the limit*: the same wall at 78–99.8 % of the maximum flow rate
   (inlet stretch 10–2000, inlet pressure up to within 1e-13 of the limit pressure);
4. *non-separable*: a script-local Carreau fluid (blood-like: μ0 = 0.056 Pa s,
   μ∞ = 3.45 mPa s, λ = 3.313 s, n = 0.3568) that implements only ``_stress``, in a thick
   neo-Hookean wall (μ = 2 kPa), q = 2e-11 … 1.2e-9 m³/s (strains 0.02–0.74). It exercises
   the generic path a rheology plugin gets: the Rabinowitsch–Mooney flow function of
   ``_stress`` alone, and its inverse.

Methods: ``coupler="auto"`` (the default), ``ClosedForm()`` (scene 1), ``Quadrature(order=k)``
for k = 4, 6, 8, 12, 16, 24, 32, ``ODE`` with DOP853, LSODA and Radau at rtol = 1e-4 … 1e-12
(atol = rtol/1000, ``check_error=False`` so that the integrator alone is timed; scene 4 uses
rtol = 1e-4, 1e-8, 1e-12 only), ``ODE(method="odeint")`` (the chapter's ``odeint`` defaults inside tubefsi) and the lean
chapter baseline of ``benchmarks/speed.py`` (a scalar, pure-float right-hand side for
``scipy.integrate.odeint`` at its default tolerances, one ODE per point; copied below so this
script stands alone). Scene 4 has no lean baseline (the chapter treats power laws only); its
ratios are against ``ODE(method="odeint")``.

Reference values (independent of tubefsi's numerics)
-----------------------------------------------------
All references are computed with ``mpmath`` at ``mp.dps = 30`` straight from the formulas of
``docs/theory.md``:

* tube laws (section "Tube laws"): thin reference ``P = μ t̄ (λ − λ⁻³)``; thick (Lamé)
  ``P = (μ/2)[f(x_o) − f(x_i)]``, ``f(x) = x + ln x``, ``x_o = b/(b − 1 + λ²)``, ``x_i = λ⁻²``,
  ``b = (1 + t̄)²``, ``μ = 2(c1 + c2)``; hand-derived slopes ``P' = μ t̄ (1 + 3 s⁻⁴)`` and
  ``P' = μ d ((d+2) s² + d) / (s³ (s² + d)²)``, ``d = b − 1`` (checked against ``mpmath.diff``
  of ``P`` when the script starts);
* power law (section "The flow law of a generalized Newtonian fluid"):
  ``G(q, R) = φ(q) R^−k``, ``k = 3n + 1``, ``φ(q) = 2m[(3n+1)q/(πn)]^n``;
  separation (section "Coupling without an ODE") with the outlet at zero pressure:
  ``L φ(q) = a^k ∫_1^λin P'(s) s^k ds``
  (a positive integrand, ``mpmath.quad`` on geometrically split intervals — no cancellation,
  also at λ = 2000). Each scene picks exact inlet stretches λ, gets ``q``, rounds it to the
  double that the methods receive, and moves λ by one Newton step so that the reference is the
  exact answer for that double (the rounding would otherwise show near the limit);
* Carreau (scene 4): with the wall shear rate γ as parameter, ``q = π R³ Q(γ)/3`` and
  ``G = 2σ(γ)/R``, ``Q(γ) = γ − I(γ)/σ(γ)³``, ``I(γ) = ∫_0^γ σ³`` in closed form (binomial
  expansion, ``∫ x³ (1 + c x²)^p dx`` is elementary). The separated identity becomes an
  integral over γ between the outlet and inlet wall shear rates,
  ``L = ∫ a s P'(s) |ds/dγ| / (2σ(γ)) dγ``, ``s = (3q/(π a³ Q(γ)))^{1/3}``,
  ``ds/dγ = −(s/3) Q'/Q``, ``Q' = 3 I σ'/σ⁴`` (``I`` and ``Q'`` are checked against
  ``mpmath.quad``/``mpmath.diff`` when the script starts). For each flow rate (a double), the
  inlet stretch is the root of that identity, by Newton's method on ``ln λ`` with the exact
  derivative ``λ P'(λ)/G(q, aλ)`` (``mp.dps = 25``).

``examples/stability_map.py`` imports this reference (``RefWall`` also has the thin
current-thickness law ``μ t̄ (1 − λ⁻⁴)``, ``P' = 4 μ t̄ λ⁻⁵``).

The error of a method is the larger relative error of pressure drop and inlet displacement,
maximised over the reference points (40 in scenes 1–3, 10 in scene 4), flow-controlled.

Timing
------
Vectorized methods (closed form, quadrature): best of 3 calls on N = 2000 flow rates spanning
the scene (N = 400 in scene 4), divided by N, after a warm-up call. Per-point methods (ODE,
odeint, the lean baseline): a call on up to 40 of the reference points — fewer when a pilot
point shows the method would exceed about 2 s — divided by the number of points; best of 3
such calls where that fits in 2 s, else one. All in
one process, so the ratios compare like with like.
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import time
import warnings

import attrs
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import mpmath  # noqa: E402
import numpy as np  # noqa: E402
from mpmath import mp, mpf  # noqa: E402

import tubefsi  # noqa: E402
from tubefsi.couplers import ODE, ClosedForm, Quadrature  # noqa: E402
from tubefsi.registry import rheologies, walls  # noqa: E402
from tubefsi.rheology import Rheology  # noqa: E402
from tubefsi.testing.reference.chapter_baseline import chapter_thick, chapter_thin  # noqa: E402

mp.dps = 30

A, T, LEN = 1e-4, 3e-5, 1e-2          # m
M_FLUID, N_FLUID = 0.017, 0.7         # Pa s^n, -
TUBE = tubefsi.Tube(radius=A, thickness=T, length=LEN)

N_VECTOR = 2000
N_REF = 40
BUDGET = 2.0                           # s of timed work per per-point method and scene
QUAD_ORDERS = (4, 6, 8, 12, 16, 24, 32)
RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
ODE_METHODS = ("DOP853", "LSODA", "Radau")
ERROR_FLOOR = 1e-16


@attrs.frozen
class Sizes:
    """How much the chart measures: the published chart by default, :data:`QUICK` for a smoke test."""

    n_ref: int = N_REF                  # reference points of scenes 1-3
    n_vector: int = N_VECTOR            # flow rates per timed call of a vectorized method, scenes 1-3
    carreau_ref: int = 10               # the same two for scene 4
    carreau_vector: int = 400
    budget: float = BUDGET
    quad_orders: tuple = QUAD_ORDERS
    rtols: tuple = RTOLS
    ode_methods: tuple = ODE_METHODS


#: ``--quick``: every scene and every kind of method once, at small sizes (seconds)
QUICK = Sizes(n_ref=3, n_vector=20, carreau_ref=2, carreau_vector=10, budget=0.01, quad_orders=(8, 24),
              rtols=(1e-6,), ode_methods=("LSODA",))


# ============================================================================ reference (mpmath)
class RefWall:
    """Tube law P(λ) and its hand-derived slope P'(λ) in mpmath (``docs/theory.md``, "Tube laws").

    ``kind``: "thin-reference" (μ t̄ (λ − λ⁻³)), "thin-current" (μ t̄ (1 − λ⁻⁴), P' = 4 μ t̄ λ⁻⁵)
    or "thick" (Lamé); ``mu`` is the shear modulus, 2 (c1 + c2) for Mooney–Rivlin.
    """

    def __init__(self, kind, mu, tb):
        self.kind, self.mu, self.tb = kind, mpf(mu), mpf(tb)

    def P(self, lam):
        mu, tb = self.mu, self.tb
        if self.kind == "thin-reference":
            return mu * tb * (lam - lam**-3)
        if self.kind == "thin-current":
            return mu * tb * (1 - lam**-4)
        b = (1 + tb) ** 2
        xo, xi = b / (b - 1 + lam**2), 1 / lam**2
        return mu / 2 * ((xo + mpmath.log(xo)) - (xi + mpmath.log(xi)))

    def dP(self, s):
        mu, tb = self.mu, self.tb
        if self.kind == "thin-reference":
            return mu * tb * (1 + 3 * s**-4)
        if self.kind == "thin-current":
            return 4 * mu * tb * s**-5
        d = (1 + tb) ** 2 - 1
        return mu * d * ((d + 2) * s**2 + d) / (s**3 * (s**2 + d) ** 2)

    def limit_pressure(self):
        if self.kind == "thin-reference":
            return mpmath.inf
        return self.mu * (self.tb if self.kind == "thin-current" else mpmath.log(1 + self.tb))

    def check_slope(self):
        for lam in (mpf("1.001"), mpf("1.7"), mpf(30)):
            num = mpmath.diff(self.P, lam)
            assert abs(num / self.dP(lam) - 1) < mpf(10) ** -20, (self.kind, lam)


def geometric_split(lo, hi):
    pts = [lo]
    while pts[-1] * 2 < hi:
        pts.append(pts[-1] * 2)
    return pts + [hi]


def ref_J(wall, lam, k):
    """∫_1^λ P'(s) s^k ds (positive integrand)."""
    return mpmath.quad(lambda s: wall.dP(s) * s**k, geometric_split(mpf(1), lam))


def ref_phi(q, n, m):
    return 2 * m * ((3 * n + 1) * q / (mpmath.pi * n)) ** n


def ref_phi_inverse(phi, n, m):
    return mpmath.pi * n / (3 * n + 1) * (phi / (2 * m)) ** (1 / n)


def power_law_reference(wall, n, m, lams, a=A, length=LEN):
    """Flow rates (doubles) and exact (Δp, u) for them, at inlet stretches near ``lams``."""
    n, m, a, length = mpf(n), mpf(m), mpf(a), mpf(length)
    k = 3 * n + 1
    qs, dps, us = [], [], []
    for lam in lams:
        lam = mpf(lam)
        J = ref_J(wall, lam, k)
        q = float(ref_phi_inverse(J * a**k / length, n, m))
        # one Newton step: the exact inlet stretch for the double q (error ~ 1e-32)
        J_target = length * ref_phi(mpf(q), n, m) / a**k
        lam = lam + (J_target - J) / (wall.dP(lam) * lam**k)
        qs.append(q)
        dps.append(wall.P(lam))
        us.append(a * (lam - 1))
    return np.array(qs), dps, us


def power_law_q_max(wall, n, m, a=A, length=LEN):
    """Maximum flow rate (limit-pressure wall, n < 1): L φ(q_max) = a^k ∫_1^∞ P' s^k ds.

    Thin current thickness: the integral is 4 μ t̄/(4 − k). Thick: s = 1/t, then t = w^(1/(4−k))
    removes the endpoint singularity, leaving a smooth integrand on [0, 1].
    """
    n, m = mpf(n), mpf(m)
    k = 3 * n + 1
    alpha = 4 - k
    if wall.kind == "thin-current":
        J_inf = 4 * wall.mu * wall.tb / alpha
    else:
        d = (1 + wall.tb) ** 2 - 1

        def integrand(w):
            t2 = w ** (2 / alpha)
            return ((d + 2) + d * t2) / (1 + d * t2) ** 2

        J_inf = wall.mu * d / alpha * mpmath.quad(integrand, [0, 1])
    return ref_phi_inverse(J_inf * mpf(a) ** k / mpf(length), n, m)


# ---------------------------------------------------------------------------- Carreau
@attrs.frozen(kw_only=True)
class Carreau(Rheology):
    """Carreau fluid σ = γ̇ [μ∞ + (μ0 − μ∞)(1 + (λγ̇)²)^((n−1)/2)]: only ``_stress``, so not separable."""

    zero_shear_viscosity: float = 0.056
    infinite_shear_viscosity: float = 0.00345
    relaxation_time: float = 3.313
    index: float = 0.3568

    def _stress(self, shear_rate):
        mu0, mui = self.zero_shear_viscosity, self.infinite_shear_viscosity
        lt, n = self.relaxation_time, self.index
        return shear_rate * (mui + (mu0 - mui) * (1.0 + (lt * shear_rate) ** 2) ** (0.5 * (n - 1.0)))


class RefCarreau:
    """The Carreau flow law in mpmath, parametrised by the wall shear rate (module docstring)."""

    def __init__(self, fluid):
        self.mui = mpf(fluid.infinite_shear_viscosity)
        self.delta = mpf(fluid.zero_shear_viscosity) - self.mui
        self.c = mpf(fluid.relaxation_time) ** 2
        self.m = (mpf(fluid.index) - 1) / 2

    def sigma(self, g):
        return g * (self.mui + self.delta * (1 + self.c * g**2) ** self.m)

    def dsigma(self, g):
        w = 1 + self.c * g**2
        return self.mui + self.delta * w**self.m + self.delta * g * self.m * w ** (self.m - 1) * 2 * self.c * g

    def I(self, g):
        """∫_0^g σ(x)³ dx, term by term: ∫_0^g x³ (1 + c x²)^p dx elementary."""
        c, W = self.c, 1 + self.c * g**2
        total = mpf(0)
        for j, binom in enumerate((1, 3, 3, 1)):
            p = j * self.m
            if p == 0:
                piece = g**4 / 4
            else:
                piece = ((W ** (p + 2) - 1) / (p + 2) - (W ** (p + 1) - 1) / (p + 1)) / (2 * c**2)
            total += binom * self.mui ** (3 - j) * self.delta**j * piece
        return total

    def Q(self, g):
        return g - self.I(g) / self.sigma(g) ** 3

    def dQ(self, g):
        return 3 * self.I(g) * self.dsigma(g) / self.sigma(g) ** 4

    def shear_rate_for(self, target):
        """γ with Q(γ) = target (Q(γ)/γ lies in (1/3, 3/4] for this law)."""
        return mpmath.findroot(lambda g: self.Q(g) - target, (target, 3 * target), solver="anderson")

    def check(self):
        """The closed forms against mpmath quadrature / differentiation."""
        for g in (mpf("0.5"), mpf(30), mpf(3000)):
            direct = mpmath.quad(lambda x: self.sigma(x) ** 3, [0, g])
            assert abs(self.I(g) / direct - 1) < mpf(10) ** -20, g
            assert abs(mpmath.diff(self.Q, g) / self.dQ(g) - 1) < mpf(10) ** -20, g


def carreau_reference(fluid, wall, qs, a=A, length=LEN):
    """Exact (Δp, u) for a Carreau fluid in ``wall`` at the flow rates ``qs`` (module docstring)."""
    ref = RefCarreau(fluid)
    ref.check()
    a, length = mpf(a), mpf(length)

    def length_for(c0, lam_in):
        """∫_1^λin P'(s)/G(q, a s) ds as an integral over the wall shear rate."""
        g_out, g_in = ref.shear_rate_for(c0), ref.shear_rate_for(c0 / lam_in**3)

        def integrand(g):
            sig, i3 = ref.sigma(g), ref.I(g)
            Q = g - i3 / sig**3
            s = (c0 / Q) ** (mpf(1) / 3)
            ds = s * i3 * ref.dsigma(g) / (Q * sig**4)          # |ds/dγ| = (s/3) Q'/Q
            return a * s * wall.dP(s) * ds / (2 * sig)

        return mpmath.quad(integrand, [g_in, g_out])

    def gradient(c0, lam):
        """G(q, aλ) = 2σ(γ_w)/(aλ), Q(γ_w) = 3q/(π a³ λ³)."""
        return 2 * ref.sigma(ref.shear_rate_for(c0 / lam**3)) / (a * lam)

    dps, us = [], []
    with mp.workdps(25):
        lam = None
        for q in qs:
            c0 = 3 * mpf(float(q)) / (mpmath.pi * a**3)
            if lam is None:                                    # linearised tube law: a first guess
                lam = 1 + length * gradient(c0, mpf(1)) / wall.dP(mpf(1))
            v = mpmath.log(lam)
            for _ in range(30):                                # Newton on v = ln λ_in
                lam = mpmath.exp(v)
                f = length_for(c0, lam) - length
                step = f / (lam * wall.dP(lam) / gradient(c0, lam))
                v = v - step if step < v else v / 2
                if abs(step) < mpf(10) ** -20 * v:
                    break
            else:
                raise RuntimeError("Carreau reference: Newton did not converge")
            lam = mpmath.exp(v)
            dps.append(wall.P(lam))
            us.append(a * mpmath.expm1(v))
    return np.asarray(qs, dtype=float), dps, us


# ============================================================================ the chapter's method
# chapter_thick, chapter_thin (imported above) come from tubefsi.testing.reference.chapter_baseline,
# shared with benchmarks/speed.py: a lean scalar odeint per point at default tolerances, returning
# (pressure drop, inlet displacement).


# ============================================================================ scenes
@attrs.frozen
class Scene:
    key: str
    title: str
    fluid: object
    wall: object
    q_ref: np.ndarray
    dp_ref: list
    u_ref: list
    baseline: object = None         # f(q) -> (dp, u), or None
    n_vector: int = N_VECTOR
    n_per_point: int = N_REF
    note: str = ""


def build_scenes(sizes=Sizes()):
    tb = TUBE.reduced_thickness
    fluid = rheologies["power-law"](consistency=M_FLUID, index=N_FLUID)
    scenes = []

    mu = 2e3
    thin = RefWall("thin-reference", mu, tb)
    thin.check_slope()
    q, dp, u = power_law_reference(thin, N_FLUID, M_FLUID, 1 + np.geomspace(0.01, 3, sizes.n_ref))
    scenes.append(Scene("thin", "1. thin neo-Hookean (ref. thickness), power law n = 0.7: closed form",
                        fluid, walls["thin-neo-hookean"](shear_modulus=mu, thickness_convention="reference"),
                        q, dp, u, baseline=lambda qi: chapter_thin(qi, N_FLUID, M_FLUID, mu, TUBE),
                        n_vector=sizes.n_vector))

    c1, c2 = 1.5e3, -0.5e3
    mu = 2 * (c1 + c2)
    thick = RefWall("thick", mu, tb)
    thick.check_slope()
    mr = walls["thick-mooney-rivlin"](c1=c1, c2=c2)
    q_max = power_law_q_max(thick, N_FLUID, M_FLUID)
    q, dp, u = power_law_reference(thick, N_FLUID, M_FLUID, 1 + np.geomspace(0.02, 1.5, sizes.n_ref))
    scenes.append(Scene("moderate", "2. thick Mooney–Rivlin, power law n = 0.7: moderate load",
                        fluid, mr, q, dp, u, baseline=lambda qi: chapter_thick(qi, N_FLUID, M_FLUID, mu, TUBE),
                        note=f"q/q_max {q.min() / float(q_max):.3g}–{q.max() / float(q_max):.3g}",
                        n_vector=sizes.n_vector))
    q, dp, u = power_law_reference(thick, N_FLUID, M_FLUID, np.geomspace(10, 2000, sizes.n_ref))
    p_lim = thick.mu * mpmath.log(1 + thick.tb)
    scenes.append(Scene("limit", "3. thick Mooney–Rivlin, power law n = 0.7: near the maximum flow rate",
                        fluid, mr, q, dp, u, baseline=lambda qi: chapter_thick(qi, N_FLUID, M_FLUID, mu, TUBE),
                        note=f"q/q_max {q.min() / float(q_max):.4f}–{q.max() / float(q_max):.4f}, "
                             f"1 - dp/p_lim down to {float(1 - max(dp) / p_lim):.1e}",
                        n_vector=sizes.n_vector))

    carreau = Carreau()
    nh = RefWall("thick", 2e3, tb)
    q, dp, u = carreau_reference(carreau, nh, np.geomspace(2e-11, 1.2e-9, sizes.carreau_ref))
    scenes.append(Scene("carreau", "4. Carreau fluid (non-separable), thick neo-Hookean",
                        carreau, walls["thick-neo-hookean"](shear_modulus=2e3), q, dp, u,
                        n_vector=sizes.carreau_vector, n_per_point=sizes.carreau_ref,
                        note="ratios against ODE(method='odeint')"))
    return scenes


# ============================================================================ measurement
def max_error(dp, u, dp_ref, u_ref):
    err = 0.0
    for a, b in zip(np.ravel(dp), dp_ref):
        err = max(err, float(abs(mpf(float(a)) / b - 1)))
    for a, b in zip(np.ravel(u), u_ref):
        err = max(err, float(abs(mpf(float(a)) / b - 1)))
    return err


def best_of(fn, repeat):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def ode(method, rtol=None):
    kw = {} if rtol is None else dict(rtol=rtol, atol=rtol * 1e-3)
    try:
        return ODE(method=method, check_error=False, **kw)
    except TypeError:             # a tubefsi without the a-posteriori check
        return ODE(method=method, **kw)


def methods_for(scene, sizes=Sizes()):
    """(family, label, coupler or callable, per_point)."""
    out = [("auto", "auto (default)", "auto", False)]
    if scene.key == "thin":
        out.append(("closed form", "ClosedForm()", ClosedForm(), False))
    for k in sizes.quad_orders:
        out.append(("quadrature", f"Quadrature(order={k})", Quadrature(order=k, check_error=False), False))
    # the generic (non-separable) flow law makes each right-hand side evaluation a root find:
    # fewer tolerances there keep the script within a few minutes
    rtols = sizes.rtols[::2] if scene.key == "carreau" else sizes.rtols
    for method in sizes.ode_methods:
        for rtol in rtols:
            if method == "Radau" and rtol < 1e-10:
                continue           # minutes per point near the limit; adds nothing to the chart
            out.append((f"ODE {method}", f"ODE({method}, rtol={rtol:.0e})", ode(method, rtol), True))
    out.append(("odeint", "ODE(method='odeint')", ode("odeint"), True))
    if scene.baseline is not None:
        out.append(("chapter", "chapter odeint (lean)", scene.baseline, True))
    return out


def repeats(pilot, count, budget=BUDGET):
    """Best of 3 for per-point methods when that fits the time budget, else a single pass."""
    return 3 if 3 * pilot * count < budget else 1


def run_method(scene, coupler, per_point, budget=BUDGET):
    """Return (time per point, error, n points timed, note)."""
    q_ref = scene.q_ref
    if callable(coupler) and not isinstance(coupler, tubefsi.couplers.Coupler):
        pilot = best_of(lambda: coupler(q_ref[-1]), 1)
        count = int(min(scene.n_per_point, max(5, budget / max(pilot, 1e-9))))
        idx = np.unique(np.linspace(0, q_ref.size - 1, count).round().astype(int))
        res = []
        elapsed = best_of(lambda: res.append([coupler(qi) for qi in q_ref[idx]]),
                          repeats(pilot, idx.size, budget))
        dp, u = zip(*res[-1])
        return elapsed / idx.size, max_error(dp, u, [scene.dp_ref[i] for i in idx],
                                             [scene.u_ref[i] for i in idx]), idx.size, ""

    def solve(q):
        return tubefsi.solve(scene.fluid, scene.wall, TUBE, flow_rate=q, coupler=coupler)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if per_point:
                pilot = best_of(lambda: solve(q_ref[-1:]), 1)
                count = int(min(scene.n_per_point, max(3, budget / max(pilot, 1e-9))))
                idx = np.unique(np.linspace(0, q_ref.size - 1, count).round().astype(int))
                sols = []
                per = best_of(lambda: sols.append(solve(q_ref[idx])), repeats(pilot, idx.size, budget)) / idx.size
                sol = sols[-1]
            else:
                idx = np.arange(q_ref.size)
                sol = solve(q_ref)
                dense = np.linspace(q_ref.min(), q_ref.max(), scene.n_vector)
                solve(dense[:10])
                per = best_of(lambda: solve(dense), 3) / scene.n_vector
        except tubefsi.TubefsiError as exc:
            return math.nan, math.nan, 0, f"raised {type(exc).__name__}"
    note = ""
    kinds = sorted({w.category.__name__ for w in caught})
    if kinds:
        note = "warned " + ", ".join(kinds)
    err = max_error(sol.pressure_drop, sol.inlet_displacement,
                    [scene.dp_ref[i] for i in idx], [scene.u_ref[i] for i in idx])
    return per, err, idx.size, note


# ============================================================================ chart
STYLE = {
    "auto": dict(color="k", marker="*", ms=14, ls="none", zorder=5),
    "closed form": dict(color="tab:green", marker="D", ms=8, ls="none", zorder=4),
    "quadrature": dict(color="tab:blue", marker="o", ms=6, ls="-", zorder=3),
    "ODE DOP853": dict(color="tab:orange", marker="s", ms=6, ls="-"),
    "ODE LSODA": dict(color="tab:red", marker="^", ms=6, ls="-"),
    "ODE Radau": dict(color="tab:purple", marker="v", ms=6, ls="-"),
    "odeint": dict(color="tab:brown", marker="P", ms=10, ls="none"),
    "chapter": dict(color="tab:gray", marker="X", ms=11, ls="none"),
}
LEGEND = {
    "auto": "tubefsi default (auto)",
    "closed form": "closed form",
    "quadrature": "Quadrature, order 4–32 (labelled)",
    "ODE DOP853": "ODE DOP853, rtol 1e-4…1e-12",
    "ODE LSODA": "ODE LSODA, rtol 1e-4…1e-12",
    "ODE Radau": "ODE Radau, rtol 1e-4…1e-10",
    "odeint": "ODE(method='odeint'): chapter's defaults in tubefsi",
    "chapter": "chapter's method (lean scalar odeint)",
}


def plot(scenes, results, path):
    fig, axes = plt.subplots(2, 2, figsize=(13, 10.5), constrained_layout=True)
    for ax, scene in zip(axes.flat, scenes):
        rows = results[scene.key]
        families = {}
        for fam, label, per, err, *_ in rows:
            if math.isfinite(per):
                families.setdefault(fam, []).append((per, max(err, ERROR_FLOOR), label))
        for fam, pts in families.items():
            x, y, labels = zip(*pts)
            ax.plot(x, y, **STYLE[fam])
            if fam == "quadrature":          # order labels, alternately left and right
                for i, (xi, yi, lab) in enumerate(zip(x, y, labels)):
                    ax.annotate(lab.split("=")[1].rstrip(")"), (xi, yi), textcoords="offset points",
                                xytext=(6, 2) if i % 2 == 0 else (-6, -9), ha="left" if i % 2 == 0 else "right",
                                fontsize=8, color="tab:blue")
        ax.axhline(1e-12, color="k", lw=0.8, ls=":")
        ax.text(0.99, 1e-12, "accuracy contract 1e-12", transform=ax.get_yaxis_transform(), ha="right",
                va="bottom", fontsize=8)
        base = [per for fam, _, per, *_ in rows if fam == ("chapter" if scene.baseline else "odeint")]
        if base and math.isfinite(base[0]):
            ax.axvline(base[0] / 100, color="k", lw=0.8, ls="--")
            what = "chapter's time" if scene.baseline else "ODE(odeint) time"
            ax.text(base[0] / 100, 0.02, f" 1/100 of the\n {what}", transform=ax.get_xaxis_transform(),
                    fontsize=8, va="bottom")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(1e-16, 1e-1)
        ax.set_xlabel("time per point (s)")
        ax.set_ylabel("max relative error (Δp, inlet displacement)")
        ax.set_title(scene.title, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    handles = [plt.Line2D([], [], **{**STYLE[f], "ls": STYLE[f]["ls"]}) for f in LEGEND]
    fig.legend(handles, list(LEGEND.values()), loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    fig.suptitle("tubefsi work–precision (errors against an independent mpmath reference; "
                 f"errors below {ERROR_FLOOR:g} drawn at it)", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ============================================================================ main
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outdir", nargs="?", default=pathlib.Path(__file__).resolve().parents[1] / "docs",
                        help="where to write work_precision.png")
    parser.add_argument("--quick", action="store_true", help="every step at small sizes (a smoke test, seconds)")
    args = parser.parse_args(argv)
    outdir = pathlib.Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sizes = QUICK if args.quick else Sizes()

    t_start = time.perf_counter()
    scenes = build_scenes(sizes)
    print(f"references: {time.perf_counter() - t_start:.1f} s (mpmath, dps {mp.dps})")
    results = {}
    for scene in scenes:
        rows = []
        for fam, label, coupler, per_point in methods_for(scene, sizes):
            per, err, count, note = run_method(scene, coupler, per_point, sizes.budget)
            rows.append((fam, label, per, err, count, note))
        base_fam = "chapter" if scene.baseline is not None else "odeint"
        base = next(per for fam, _, per, *_ in rows if fam == base_fam)
        results[scene.key] = rows
        print(f"\n{scene.title}" + (f"  ({scene.note})" if scene.note else ""))
        print(f"  {'method':28s} {'max rel. error':>14s} {'time/point':>12s} {'points':>6s} "
              f"{'speed-up vs chapter':>20s}  note")
        for fam, label, per, err, count, note in rows:
            ratio = base / per if math.isfinite(per) else math.nan
            per_s = f"{per * 1e6:9.2f} us" if math.isfinite(per) else "         -"
            print(f"  {label:28s} {err:14.1e} {per_s:>12s} {count:6d} {ratio:19.1f}x  {note}")
    path = outdir / "work_precision.png"
    plot(scenes, results, path)
    print(f"\nwrote {path} ({time.perf_counter() - t_start:.0f} s in all)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
