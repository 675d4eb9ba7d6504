r"""The chapter's equations as printed, its linear closed forms, and its two figures.

The source chapter (Anand & Christov, *On the deformation of a hyperelastic tube due to
steady viscous flow within*) prints several formulas inconsistently; they are listed, each
with the test that demonstrates it, in ``docs/verification.md``, section "The chapter's
printed inconsistencies". This module evaluates them **as printed**, to reproduce the
chapter's figures and to show what changes once they are made consistent — not for use:
tubefsi's solvers implement the derived forms (``docs/theory.md``).

* :func:`printed_thin_pressure_drop` — the thin-wall closed form without the factor 3 (item 2);
  :func:`thin_reference_pressure_drop` — the same with the factor restored;
* :func:`printed_thick_pressure_drop` — the thick-wall deflection ODE without the factor 4
  (item 3; ``factor=4`` restores it);
* :func:`linear_pressure_drop` — the chapter's (correct) linear-wall closed forms;
* :func:`chapter_curves` and :func:`reproduce_chapter` — the two figures, as printed
  (:math:`\gamma = \beta/3`) and consistent (:math:`\gamma = 3\beta`, solved by tubefsi).

Variables are the chapter's dimensionless ones (:mod:`tubefsi.dimensionless`):
:math:`\bar q`, :math:`\Delta\bar p = \Delta p/\mathcal P_c`, :math:`\gamma`, :math:`\beta`.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from scipy import integrate
from scipy.optimize import elementwise

from .numerics.kernels import as_output as _out
from ._validation import nonnegative_array as _nonnegative_array
from ._validation import positive_scalar as _positive
from .dimensionless import scene
from .errors import ConvergenceError, InvalidParameterError
from .solve import solve_unchecked
from .validity import SLENDERNESS

__all__ = [
    "printed_thin_pressure_drop", "thin_reference_pressure_drop", "printed_thick_pressure_drop",
    "linear_pressure_drop", "CHAPTER_PARAMETERS", "chapter_curves", "reproduce_chapter",
]


# ------------------------------------------------------------------------------- the printed forms
def _flow_factor(n, qbar):
    r""":math:`X = [(3+1/n)\bar q]^n`: the lubrication law is :math:`d\bar p/d\bar z = -2X\bar R^{-(3n+1)}`."""
    return ((3.0 + 1.0 / n) * np.asarray(qbar, dtype=float)) ** n


def _pow_ratio(k, log_lam):
    r""":math:`(\lambda^k - 1)/k` from :math:`\ln\lambda`, stable, :math:`\ln\lambda` at k = 0."""
    return log_lam if k == 0 else np.expm1(k * log_lam) / k


def _solve_strain(func, target):
    """Strain e >= 0 with func(e) = target (func increasing from 0), vectorized."""
    target = np.asarray(target, dtype=float)

    def f(e, t):
        return func(e) - t

    safe = np.where(target > 0, target, 1.0)
    br = elementwise.bracket_root(f, np.zeros_like(safe), np.full_like(safe, 1e-3), xmin=0.0, args=(safe,))
    res = elementwise.find_root(f, br.bracket, args=(safe,),
                                tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
    if not np.all(br.success | (target == 0)):
        raise ConvergenceError("the thin closed form has no root for some flow rate (target too large)")
    return np.where(target > 0, res.x, 0.0)


def _thin_reference_pressure(e, gam):
    """gamma p = lam - lam^-3 = ((1+e)^4 - 1)/(1+e)^3, without cancellation."""
    return e * (4.0 + e * (6.0 + e * (4.0 + e))) / (1.0 + e) ** 3 / gam


def printed_thin_pressure_drop(index, gamma, qbar):
    r"""Thin-wall :math:`\Delta\bar p(\bar q)` from the chapter's closed form **as printed**.

    Eq. (flowrate_deflection_nondim):
    :math:`2\gamma X(1-\bar z) = \frac{\lambda^{3n+2}}{3n+2} + \frac{\lambda^{3n-2}}{3n-2} - \frac{6n}{(3n+2)(3n-2)}`
    (the second term lacks the factor 3 of :math:`d(\lambda-\lambda^{-3})/d\lambda = 1 + 3\lambda^{-4}`),
    then :math:`\Delta\bar p = (\lambda_0 - \lambda_0^{-3})/\gamma`.
    """
    return _thin_closed_form(index, gamma, qbar, second=1.0)


def thin_reference_pressure_drop(index, gamma, qbar):
    r"""The same with the factor 3 restored: the closed form that follows from the chapter's
    thin tube law :math:`\gamma\bar p = \lambda - \lambda^{-3}` and its flow law,
    :math:`2\gamma X = \frac{\lambda^{3n+2}-1}{3n+2} + 3\,\frac{\lambda^{3n-2}-1}{3n-2}`."""
    return _thin_closed_form(index, gamma, qbar, second=3.0)


def _thin_closed_form(index, gam, qbar, *, second):
    n, gam = _positive("index", index), _positive("gamma", gam)
    q = _nonnegative_array("qbar", qbar)
    target = 2.0 * gam * _flow_factor(n, q)

    def lhs(e):
        ln = np.log1p(e)
        return _pow_ratio(3 * n + 2, ln) + second * _pow_ratio(3 * n - 2, ln)

    e0 = _solve_strain(lhs, target)
    return _out(_thin_reference_pressure(e0, gam), np.ndim(qbar) == 0)


def _thick_law(lam, tb, strain=None):
    r""":math:`f(x_o) - f(x_i) = p/(c_1+c_2)`, :math:`f(x) = x + \ln x` (eq. pressure_deformation_thick), stable."""
    b = (1.0 + tb) ** 2
    d = b - 1.0
    e = lam - 1.0 if strain is None else strain
    x = e * (2.0 + e)
    return np.log1p(x * d / (b + x)) + x * d / ((1.0 + x) * (b + x))


def _thick_brace(u, tb):
    r"""The brace :math:`B(\bar u)` of eq. (non_dim_flow_rate_coupled_thick), as printed.

    It equals :math:`-P'(\lambda)/(c_1+c_2)` (:func:`_thick_slope`), but its four terms of
    size :math:`2/\lambda` cancel to :math:`O(\lambda^{-5})`: use it for moderate strains only.
    """
    b = (1.0 + tb) ** 2
    lam = 1.0 + u
    den = b + u * u + 2.0 * u
    return 2.0 * b * lam / den**2 + 2.0 * lam / den - 2.0 / lam - 2.0 / lam**3


def _thick_slope(lam, tb):
    r""":math:`-B = d[f(x_o) - f(x_i)]/d\lambda = 2\lambda d\,[\lambda^2(d+2) + d]/[\lambda^4(\lambda^2+d)^2]`,
    :math:`d = (1+\bar t)^2 - 1`: the printed brace without its cancellation."""
    d = tb * (2.0 + tb)
    lam2 = lam * lam
    return 2.0 * lam * d * (lam2 * (d + 2.0) + d) / (lam2 * lam2 * (lam2 + d) ** 2)


def printed_thick_pressure_drop(index, gamma, qbar, reduced_thickness, *, factor=1.0, max_stretch=1e6):
    r"""Thick-wall :math:`\Delta\bar p(\bar q)` from the chapter's deflection ODE **as printed**.

    Eq. (non_dim_flow_rate_coupled_thick): :math:`B(\bar u)\,d\bar u/d\bar z =
    \text{factor}\cdot\bar t\gamma X(1+\bar u)^{-(1+3n)}`, :math:`\bar u(1) = 0`, then
    :math:`2\bar t\gamma\Delta\bar p = f(x_o) - f(x_i)` at :math:`\bar u(0)`
    (eq. deflection_pressure_thick_nondim). The chapter prints ``factor = 1``; the thick tube
    law and the flow law give ``factor = 4``.

    The ODE is separable: :math:`\int_0^{\bar u(0)} (-B)(1+\bar u)^{1+3n}\,d\bar u = \text{factor}
    \cdot\bar t\gamma X`. The left side is integrated once per curve (in :math:`\ln\lambda`,
    ``solve_ivp`` DOP853, rtol 1e-12, with :math:`B` in its cancellation-free form), then
    inverted per point; this solves the printed equation far more accurately than the
    chapter's ``odeint`` at default tolerances. Flow rates the ODE cannot reach (for
    ``n < 1`` the integral converges as :math:`\bar u\to\infty`) give ``nan``.
    """
    n, gam = _positive("index", index), _positive("gamma", gamma)
    tb = _positive("reduced_thickness", reduced_thickness)
    q = _nonnegative_array("qbar", qbar)
    target = factor * tb * gam * _flow_factor(n, q)

    def rhs(v, y):                                   # v = ln(lambda); du = lambda dv
        lam = np.exp(v)
        return [_thick_slope(lam, tb) * lam ** (2.0 + 3.0 * n)]

    sol = integrate.solve_ivp(rhs, (0.0, math.log(max_stretch)), [0.0], method="DOP853", rtol=1e-12,
                              atol=1e-15, dense_output=True)
    total = sol.y[0, -1]

    def reach(v, t):
        return sol.sol(v)[0] - t

    flat = np.ravel(target)
    inside = (flat > 0) & (flat < total)
    v0 = np.full(flat.shape, np.nan)
    v0[flat == 0] = 0.0
    if np.any(inside):
        hi = np.full(int(inside.sum()), float(sol.t[-1]))
        res = elementwise.find_root(reach, (np.zeros_like(hi), hi), args=(flat[inside],),
                                    tolerances=dict(xrtol=4 * np.finfo(float).eps, xatol=1e-300))
        v0[inside] = res.x
    dp = _thick_law(np.exp(v0), tb, strain=np.expm1(v0)) / (2.0 * tb * gam)
    return _out(dp.reshape(np.shape(target)), np.ndim(qbar) == 0)


def linear_pressure_drop(index, beta, qbar, *, reduced_thickness=None, poisson_ratio=0.5):
    r"""Linear-wall :math:`\Delta\bar p(\bar q)`: the chapter's eq. (q-dp-linear-elastic) (thin,
    ``reduced_thickness=None``, :math:`K = 1-\nu/2`) or eq. (q-dp-linear-elastic-thick)
    (:math:`K = [(1+\bar t)^2(1+\nu) + 1 - 2\nu]/(2+\bar t)`):
    :math:`\Delta\bar p = \frac{1}{K\beta}\left(\{1 + 2(2+3n)K\beta X\}^{1/(2+3n)} - 1\right)`.
    Both follow from the linear tube laws; tubefsi's ``thin-linear``/``thick-linear`` agree."""
    n, b = _positive("index", index), _positive("beta", beta)
    q = _nonnegative_array("qbar", qbar)
    nu = float(poisson_ratio)
    if reduced_thickness is None:
        k = 1.0 - 0.5 * nu
    else:
        tb = _positive("reduced_thickness", reduced_thickness)
        k = ((1.0 + tb) ** 2 * (1.0 + nu) + (1.0 - 2.0 * nu)) / (2.0 + tb)
    kb = k * b
    x = _flow_factor(n, q)
    dp = np.expm1(np.log1p(2.0 * (2.0 + 3.0 * n) * kb * x) / (2.0 + 3.0 * n)) / kb
    return _out(dp, np.ndim(qbar) == 0)


# ------------------------------------------------------------------------------- the figures
#: The parameters of the reproduced figures (the chapter prints none; these are in its ranges).
CHAPTER_PARAMETERS = {
    "indices": (1.0, 0.7),               # panels (a) Newtonian, (b) shear-thinning
    "betas": (0.5, 1.0, 2.0),            # the curve labels, "beta (= 3 gamma)" in the chapter
    "qbar": (0.0, 1.0),                  # flow-rate axis
    "points": 201,
    "thick_reduced_thickness": 0.3,
    "poisson_ratio": 0.5,
}


def chapter_curves(figure, variant, *, points=None, parameters=None):
    r"""The curves of one reproduced figure as a list of dicts (one per curve).

    ``figure``: ``"thin"`` or ``"thick"``; ``variant``: ``"printed"`` (hyperelastic curve at
    :math:`\gamma = \beta/3` from the printed closed form / ODE, as the chapter labels them) or
    ``"consistent"`` (``tubefsi.solve`` of the physical scene at :math:`\gamma = 3\beta`, i.e. the
    same small-strain Young's modulus as the dashed linear curve). Each dict holds ``n``,
    ``beta`` (the label), ``gamma`` (used), ``wall`` (``"hyperelastic"``/``"linear"``), ``qbar``,
    ``dpbar`` (``nan`` where no steady state exists) and ``qbar_max``. Thin walls use the
    chapter's reference-thickness law, whose :math:`\Delta\bar p(\bar q; \gamma)` does not depend on
    :math:`\bar t` (the scene uses :math:`\bar t = 0.1`).
    """
    if figure not in ("thin", "thick"):
        raise InvalidParameterError("figure", "{'thin', 'thick'}", figure)
    if variant not in ("printed", "consistent"):
        raise InvalidParameterError("variant", "{'printed', 'consistent'}", variant)
    par = {**CHAPTER_PARAMETERS, **(parameters or {})}
    qbar = np.linspace(*par["qbar"], points or par["points"])
    tb = par["thick_reduced_thickness"] if figure == "thick" else None
    nu = par["poisson_ratio"]
    curves = []
    for n in par["indices"]:
        for b in par["betas"]:
            # hyperelastic
            if variant == "printed":
                g = b / 3.0
                if figure == "thin":
                    dp = printed_thin_pressure_drop(n, g, qbar)
                else:
                    dp = printed_thick_pressure_drop(n, g, qbar, tb)
                qmax = float(qbar[np.isfinite(dp)][-1]) if np.isnan(dp).any() else math.inf
                slender = None
            else:
                g = 3.0 * b
                wall = "thin-mooney-rivlin" if figure == "thin" else "thick-mooney-rivlin"
                opts = {"thickness_convention": "reference"} if figure == "thin" else None
                sc = scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar, gamma=g, wall=wall,
                           wall_options=opts)
                qmax = sc.max_qbar()
                ok = qbar < qmax
                dp = np.full(qbar.shape, np.nan)
                dp[ok], slender = _unchecked(scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar[ok], gamma=g,
                                                   wall=wall, wall_options=opts))
            curves.append(dict(n=n, beta=b, gamma=g, wall="hyperelastic", qbar=qbar, dpbar=np.asarray(dp),
                               qbar_max=qmax, max_inlet_strain=None, max_slenderness=slender))
            # linear (nu = 1/2): the chapter's closed forms, or tubefsi for the consistent variant
            if variant == "printed":
                dpl = linear_pressure_drop(n, b, qbar, reduced_thickness=tb, poisson_ratio=nu)
                strain = None
            else:
                # the chapter draws its linear walls far beyond small strain, to compare them with the
                # hyperelastic ones: solved without the validity warning, the largest strain reported
                lin = scene(index=n, reduced_thickness=tb or 0.1, qbar=qbar, beta=b,
                            wall="thin-linear" if figure == "thin" else "thick-linear",
                            wall_options={"poisson_ratio": nu})
                dpl, slender = _unchecked(lin)
                strain = slender * lin.tube.length / lin.tube.radius - 1.0
            curves.append(dict(n=n, beta=b, gamma=b * 2.0 * (1.0 + nu), wall="linear", qbar=qbar,
                               dpbar=np.asarray(dpl), qbar_max=math.inf, max_inlet_strain=strain))
    return curves


def _unchecked(sc):
    """``(dimensionless pressure drops, largest R_in/L)`` of a dimensionless scene, solved without
    the validity warnings: the chapter draws its curves beyond small strain (linear walls) and, in
    the physical scene that stands for its dimensionless one, beyond slender tubes; the
    figure reports how far instead."""
    sol = solve_unchecked(sc.rheology, sc.wall, sc.tube, flow_rate=sc.flow_rate)
    dp = np.asarray(sol.pressure_drop) / sc.pressure_scale
    inlet = np.asarray(sol.inlet_radius, dtype=float)
    return dp, float(np.max(inlet, initial=sc.tube.radius)) / sc.tube.length


def _title(figure, variant, tb):
    wall = "Thin wall" if figure == "thin" else f"Thick wall (t/a = {tb:g})"
    if variant == "printed":
        error = "closed form without the factor 3" if figure == "thin" else "deflection ODE without the factor 4"
        return f"{wall}, as printed: hyperelastic at γ = β/3, {error}"
    return f"{wall}, consistent: hyperelastic at γ = 3β (the same E = 3μ as the linear wall), tubefsi"


#: What the figures' symbols mean, printed on every figure (``docs/verification.md``).
_DEFINITIONS = (r"$\Delta\bar p = \Delta p/\mathcal{P}_c$ and $\bar q = q/(\mathcal{V}_z\,\pi a^2)$ at a fixed "
               r"pressure scale $\mathcal{P}_c$, with $\mathcal{V}_z = [a^{n+1}\mathcal{P}_c/(mL)]^{1/n}$; "
               r"$\beta = \mathcal{P}_c/(E\,\bar t)$, $\gamma = \mathcal{P}_c/(\mu\,\bar t)$, $\bar t = t/a$"
               "\n(power-law fluid $\\tau = m\\dot\\gamma^n$ in a tube of radius $a$, thickness $t$, length $L$; "
               "wall of Young's modulus $E$, shear modulus $\\mu$)")


def _figure(figure, variant, curves, par, colors):
    """One reproduced figure: a panel per flow index, :math:`\\bar q` against :math:`\\Delta\\bar p`
    (flow rate up, pressure drop across, as the flow curves of :mod:`tubefsi.plotting`), the
    symbols defined under the legend."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(par["indices"]), figsize=(11.5, 5.9), layout="constrained")
    axes = np.atleast_1d(axes)
    for ax, n in zip(axes, par["indices"]):
        for color, b in zip(colors, par["betas"]):
            for c in curves:
                if c["n"] != n or c["beta"] != b:
                    continue
                hyper = c["wall"] == "hyperelastic"
                label = (f"β = {b:g}, hyperelastic (γ = {c['gamma']:.3g})" if hyper
                         else f"β = {b:g}, linear")
                ax.plot(c["dpbar"], c["qbar"], "-" if hyper else "--", color=color, lw=2.0 if hyper else 1.6,
                        label=label)
                if hyper and math.isfinite(c["qbar_max"]) and c["qbar_max"] <= c["qbar"][-1]:
                    ok = np.isfinite(c["dpbar"])
                    ax.plot(c["dpbar"][ok][-1], c["qbar"][ok][-1], "x", color=color, ms=9, mew=2)
        kind = "Newtonian" if n == 1 else ("shear-thinning" if n < 1 else "shear-thickening")
        ax.set_title(f"n = {n:g} ({kind})", fontsize=12)
        ax.set_xlabel(r"dimensionless pressure drop $\Delta\bar p$", fontsize=12)
        ax.set_ylabel(r"dimensionless flow rate $\bar q$", fontsize=12)
        ax.set_ylim(par["qbar"])
        ax.set_xlim(left=0.0)
        ax.tick_params(labelsize=10)
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()   # one column per beta
    legend = fig.legend(handles, labels, loc="outside lower center", ncol=len(par["betas"]), fontsize=10,
                        frameon=False, title=_DEFINITIONS, title_fontsize=9.5)
    legend.get_title().set_multialignment("center")
    note = ("solid: hyperelastic Mooney–Rivlin, dashed: linear (ν = 1/2)"
            + ("; ×: last steady state (maximum flow rate)" if any(
                math.isfinite(c["qbar_max"]) and c["qbar_max"] <= c["qbar"][-1] for c in curves) else ""))
    fig.suptitle(_title(figure, variant, par["thick_reduced_thickness"]) + "\n" + note, fontsize=11.5)
    return fig


def _write_csv(path, figure, variant, curves):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["figure", "variant", "n", "beta_label", "gamma_used", "wall", "qbar", "dpbar"])
        for c in curves:
            for qb, dp in zip(c["qbar"], c["dpbar"]):
                w.writerow([figure, variant, f"{c['n']:g}", f"{c['beta']:g}", f"{c['gamma']:.12g}", c["wall"],
                            f"{qb:.12g}", f"{dp:.12g}" if np.isfinite(dp) else ""])
    return path


def reproduce_chapter(output_dir="chapter-figures", *, points=None, parameters=None, formats=("png", "csv"),
                      file=None):
    """Write the chapter's two figures, as printed and consistent, as PNG and CSV.

    Four figures ``{thin,thick}_{printed,consistent}.png`` (two panels each: n = 1 and
    n = 0.7; solid hyperelastic, dashed linear, one colour per beta label) and the same
    curves as ``.csv`` (long format: figure, variant, n, beta_label, gamma_used, wall, qbar,
    dpbar; an empty dpbar where no steady state exists). ``formats`` picks ``"png"`` and/or
    ``"csv"``; ``parameters`` overrides entries of :data:`CHAPTER_PARAMETERS`. Returns the
    written paths; prints the parameter values and the paths to ``file`` if given.
    """
    for f in formats:
        if f not in ("png", "csv"):
            raise InvalidParameterError("formats", "a subset of {'png', 'csv'}", f)
    import matplotlib.pyplot as plt

    out = Path(output_dir)
    out.mkdir(parents=True, exist_ok=True)
    par = {**CHAPTER_PARAMETERS, **(parameters or {})}
    written = []
    largest = {}                  # the largest inlet strain of a linear wall, per figure
    slenderest = {}               # the largest R_in/L of a hyperelastic curve's scene, per figure
    colors = plt.get_cmap("viridis")(np.linspace(0.0, 0.8, len(par["betas"])))
    for figure in ("thin", "thick"):
        for variant in ("printed", "consistent"):
            curves = chapter_curves(figure, variant, points=points, parameters=par)
            stem = f"{figure}_{variant}"
            strains = [c["max_inlet_strain"] for c in curves if c.get("max_inlet_strain") is not None]
            if strains:
                largest[figure] = max(strains)
            ratios = [c["max_slenderness"] for c in curves if c.get("max_slenderness") is not None]
            if ratios:
                slenderest[figure] = max(ratios)
            if "csv" in formats:
                written.append(_write_csv(out / f"{stem}.csv", figure, variant, curves))
            if "png" not in formats:
                continue
            fig = _figure(figure, variant, curves, par, colors)
            fig.savefig(out / f"{stem}.png", dpi=110)
            plt.close(fig)
            written.append(out / f"{stem}.png")
    if file is not None:
        print(f"chapter figures: n in {par['indices']}, beta labels {par['betas']}, "
              f"qbar in [{par['qbar'][0]:g}, {par['qbar'][1]:g}] ({points or par['points']} points), "
              f"thick t/a = {par['thick_reduced_thickness']:g}, linear nu = {par['poisson_ratio']:g}; "
              "printed: gamma = beta/3, consistent: gamma = 3 beta", file=file)
        for figure, strain in largest.items():
            print(f"{figure} linear walls reach inlet strains up to {strain:.3g}, beyond the small-strain range "
                  "(5 %) of linear elasticity: drawn as the chapter draws them, to compare", file=file)
        for figure, ratio in slenderest.items():
            if ratio > SLENDERNESS:
                print(f"{figure} hyperelastic curves reach R_in/L = {ratio:.3g} (beyond slender, {SLENDERNESS:g}) in "
                      "the physical scene that stands for them: the chapter's lubrication model, drawn as the "
                      "chapter draws it", file=file)
        for p in written:
            print(f"wrote {p}", file=file)
    return written
