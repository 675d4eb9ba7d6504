r"""Matplotlib views of tube laws, flow curves and solutions.

Every function draws on the Axes it is given (``ax=``/``axes=``) or on a new
figure, and returns what it drew on; nothing here calls ``plt.show()`` or picks a
backend, so the module is safe in scripts, notebooks and headless test runs
(``MPLBACKEND=Agg``). :mod:`matplotlib.pyplot` is imported only when a function
is called.

* :func:`plot_tube_law` — transmural pressure against hoop stretch, with the
  small-strain tangent and the limit pressure (returns the Axes);
* :func:`plot_flow_curve` — flow rate against pressure drop, with the rigid-tube
  (generalized Hagen–Poiseuille) curve (Axes);
* :func:`plot_profiles` — pressure :math:`p(z)` and radius :math:`R(z)/a` (Figure);
* :func:`plot_deformed_tube` — the inflated tube in :math:`(z, r)`, lumen coloured by
  pressure (Axes);
* :func:`plot_velocity_profiles` — axial velocity :math:`v(r)` at a few sections (Axes);
* :func:`plot_network` — a solved :class:`~tubefsi.Network`, coloured by pressure, tubes as
  wide as their deformed radius (Axes).

``WallModel.plot`` and ``Solution.plot`` are shortcuts for :func:`plot_tube_law`
and :func:`plot_profiles`. Quantities are SI except lengths on the axes of
solution plots, which are in millimetres (and velocities in mm/s), the natural
scale of the microfluidic tubes tubefsi is made for.

Example::

    import tubefsi
    from tubefsi import plotting

    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    fluid = tubefsi.registry.rheologies["power-law"](consistency=0.017, index=0.7)
    wall = tubefsi.registry.walls["thick-neo-hookean"](shear_modulus=2e3)
    ax = plotting.plot_flow_curve(fluid, wall, tube)
    ax.figure.savefig("flow_curve.png", dpi=150)
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from . import registry
from .errors import InvalidParameterError, NoSteadyStateError, StretchRangeError
from .solve import max_flow_rate, solve
from .walls.hyperelastic import HyperelasticWall

__all__ = [
    "plot_tube_law",
    "plot_flow_curve",
    "plot_profiles",
    "plot_deformed_tube",
    "plot_velocity_profiles",
    "plot_network",
]

_MM = 1e3            # metres -> millimetres
_TANGENT_GID = "tubefsi-small-strain-tangent"


# ---------------------------------------------------------------------------- helpers
def _pyplot():
    import matplotlib.pyplot as plt

    return plt


def _new_axes(ax, figsize):
    """``ax`` itself, or the single Axes of a new constrained-layout figure."""
    if ax is not None:
        return ax
    _, ax = _pyplot().subplots(figsize=figsize, layout="constrained")
    return ax


def _model_name(model, kind) -> str:
    reg = {"wall": registry.walls, "rheology": registry.rheologies}[kind]
    try:
        name = reg.name_of(model)
    except Exception:  # a broken plugin must not break a plot
        name = None
    return name or type(model).__name__


def _check_count(name, n, low=2):
    try:
        n = int(n)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, f"integers >= {low}", n) from None
    if n < low:
        raise InvalidParameterError(name, f"integers >= {low}", n)
    return n


def _fmt(x, unit="") -> str:
    """Compact engineering-style number for titles and annotations."""
    if x == 0 or not math.isfinite(x):
        s = f"{x:g}"
    elif 1e-2 <= abs(x) < 1e5:
        s = f"{x:.4g}"
    else:
        s = f"{x:.3g}"
    return f"{s} {unit}".rstrip()


def _incompressible(wall) -> bool:
    """Whether the wall conserves its cross-sectional area (so its outer radius is known)."""
    if wall.is_rigid or isinstance(wall, HyperelasticWall):
        return True
    return getattr(wall, "poisson_ratio", None) == 0.5


def _column(x, solution):
    """Positions ``x`` (1-d) shaped to broadcast against the solution's loads: ``(M, 1, ...)``."""
    return np.asarray(x, dtype=float).reshape((-1,) + (1,) * np.ndim(solution.flow_rate))


def _along(method, x, solution):
    """``method(x)`` for 1-d ``x`` on a single-load solution, as a 1-d array."""
    return np.ravel(np.asarray(method(_column(x, solution)), dtype=float))


def _scalar_solution(solution, func):
    """``(flow_rate, pressure_drop)`` floats of a single-load solution; reject a curve."""
    q = np.asarray(solution.flow_rate, dtype=float)
    if q.size != 1:
        raise InvalidParameterError(
            "solution", "single-load solutions", f"a solution of {q.size} loads",
            f"{func} draws one load; solve with a scalar flow_rate or pressure_drop, "
            "or use plot_profiles for a curve")
    return float(q.reshape(())), float(np.asarray(solution.pressure_drop, dtype=float).reshape(()))


def _subset(solution, max_loads):
    """A solution restricted to at most ``max_loads`` loads, evenly spread over the curve.

    Profiles of the subset cost ``max_loads`` root solves per position instead of one
    per load. Returns the subset and the selected flow rates (1-d).
    """
    state = solution.state
    q = np.ravel(np.asarray(state.flow_rate, dtype=float))
    order = np.argsort(q, kind="stable")
    if q.size > max_loads:
        pick = order[np.unique(np.round(np.linspace(0, q.size - 1, max_loads)).astype(int))]
    else:
        pick = order
    fields = {f.name: np.ravel(np.asarray(getattr(state, f.name)))[pick] for f in attrs.fields(type(state))}
    sub = attrs.evolve(solution, state=attrs.evolve(state, **fields), scalar=False)
    return sub, q[pick]


# ---------------------------------------------------------------------------- tube law
def plot_tube_law(wall, reduced_thickness, *, ax=None, max_stretch=3.0, normalize=True, label=None,
                  color=None):
    r"""Plot a wall's tube law: transmural pressure :math:`p` against hoop stretch :math:`\lambda = R/a`.

    Parameters
    ----------
    wall : WallModel
    reduced_thickness : float
        :math:`\bar t = t/a`.
    ax : matplotlib Axes, optional
        Draw here (several walls can share one Axes); a new figure otherwise.
    max_stretch : float
        Right end of the stretch axis (> 1); clipped just below the wall's own
        maximum stretch, if it has one.
    normalize : bool
        Divide pressures by the small-strain modulus :math:`k_0 = dp/d\lambda|_{\lambda=1}`
        (then every law starts with slope 1); otherwise plot pressures in Pa.
    label : str, optional
        Legend entry; defaults to the wall's registered name.
    color : matplotlib color, optional
        Colour of the curve (and its limit line); the Axes' colour cycle otherwise.

    Draws the tube law (solid), its linear small-strain tangent :math:`k_0(\lambda-1)`
    (faint; with ``normalize`` drawn once per Axes, since it is then the same line for
    every wall) and, when finite, the limit pressure as a dashed horizontal line in the
    curve's colour. A rigid wall is the vertical line :math:`\lambda = 1` only.

    Returns
    -------
    matplotlib.axes.Axes
    """
    tb = wall._check_thickness(reduced_thickness)
    try:
        max_stretch = float(max_stretch)
    except (TypeError, ValueError):
        raise InvalidParameterError("max_stretch", "(1, inf)", max_stretch) from None
    if not (math.isfinite(max_stretch) and max_stretch > 1.0):
        raise InvalidParameterError("max_stretch", "(1, inf)", max_stretch)
    label = _model_name(wall, "wall") if label is None else label
    ax = _new_axes(ax, (6.0, 4.2))
    ax.set_xlabel(r"hoop stretch $\lambda = R/a$")
    if normalize:
        ax.set_ylabel(r"$p\,/\,k_0$   ($k_0 = dp/d\lambda$ at $\lambda = 1$)")
    else:
        ax.set_ylabel("transmural pressure $p$ (Pa)")
    if not ax.get_title():
        ax.set_title(f"Tube law, $t/a$ = {tb:.3g}")

    if wall.is_rigid:
        ax.axvline(1.0, color="0.15" if color is None else color, lw=2.0, label=label)
        # keep the stretch axis as wide as for the other walls, without freezing autoscaling
        ax.update_datalim([(1.0, 0.0), (max_stretch, 0.0)], updatey=False)
        ax.autoscale_view()
        ax.grid(True, alpha=0.25)
        ax.legend(frameon=False)
        return ax

    lam_cap = wall.max_stretch(tb)
    hi = max_stretch if not math.isfinite(lam_cap) else min(max_stretch, 1.0 + (lam_cap - 1.0) * (1 - 1e-6))
    lam = np.linspace(1.0, hi, 400)
    p = np.asarray(wall.pressure(lam, tb), dtype=float)
    k0 = wall.small_strain_modulus(tb)
    scale = k0 if normalize else 1.0
    (line,) = ax.plot(lam, p / scale, lw=2.0, label=label, color=color)
    line.sticky_edges.y.append(0.0)   # pressures start at 0, even on a shared Axes
    color = line.get_color()

    # the small-strain tangent, drawn only as high as the curves go (so it does not set the scale)
    lim = wall.limit_pressure(tb)
    top = max(float(p[-1]), lim if math.isfinite(lim) else 0.0) * 1.08
    lam_t = np.linspace(1.0, min(hi, 1.0 + top / k0), 50)
    if not normalize:
        ax.plot(lam_t, k0 * (lam_t - 1.0), color=color, lw=1.0, alpha=0.35, ls="-",
                label="_nolegend_", gid=_TANGENT_GID)
    else:
        existing = [ln for ln in ax.get_lines() if ln.get_gid() == _TANGENT_GID]
        if existing:
            old = existing[0]
            x0 = np.asarray(old.get_xdata(), dtype=float)
            if lam_t[-1] > x0[-1]:
                old.set_data(lam_t, lam_t - 1.0)
                ax.relim()
                ax.autoscale_view()
        else:
            ax.plot(lam_t, lam_t - 1.0, color="0.5", lw=1.0, alpha=0.6,
                    label="small-strain tangent", gid=_TANGENT_GID)

    if math.isfinite(lim):
        ax.axhline(lim / scale, color=color, lw=1.0, ls="--", label="_nolegend_")
        ax.annotate(f"limit {_fmt(lim, 'Pa')}", xy=(hi, lim / scale), xytext=(-4, 3),
                    textcoords="offset points", ha="right", va="bottom", color=color, fontsize=8)
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False)
    return ax


# ---------------------------------------------------------------------------- flow curve
def _default_flow_rates(scene_sol, tube, n, outlet_pressure):
    """``0..0.9 q_max`` if the maximum flow rate is finite, else a rigid-tube estimate.

    The estimate is the rigid-tube flow rate at a pressure drop of the wall's
    small-strain modulus (the pressure that would double the radius by the linear
    law), capped at 90 % of the limit pressure; 1 kPa for a rigid wall.
    """
    fluid, wall = scene_sol.rheology, scene_sol.wall
    q_max = max_flow_rate(fluid, wall, tube, outlet_pressure=outlet_pressure)
    if math.isfinite(q_max):
        return np.linspace(0.0, 0.9 * q_max, n), q_max
    tb = tube.reduced_thickness
    if wall.is_rigid:
        dp = 1e3
    else:
        dp = wall.small_strain_modulus(tb)
        lim = wall.limit_pressure(tb)
        if math.isfinite(lim):
            dp = min(dp, 0.9 * (lim - outlet_pressure))
    q_hi = float(fluid.flow_rate(tube.radius, dp / tube.length))
    return np.linspace(0.0, q_hi, n), q_max


def plot_flow_curve(rheology, wall, tube, *, flow_rates=None, ax=None, n=200, label=None,
                    rigid=True, color=None, outlet_pressure=0.0, coupler="auto"):
    r"""Plot the flow curve: flow rate :math:`q` against pressure drop :math:`\Delta p`.

    Parameters
    ----------
    rheology, wall : model instance, class or registered name (as for :func:`tubefsi.solve`)
    tube : Tube
    flow_rates : array_like, optional
        Flow rates (m^3/s). By default ``n`` points from 0 to 90 % of the maximum
        flow rate where that is finite (or of the largest flow rate the solver reaches, if
        less: for a power law with n close to 1 the inlet radius diverges long before
        :math:`q_{max}`), else from 0 to the rigid-tube flow rate at a
        pressure drop of the wall's small-strain modulus (capped at 90 % of its limit
        pressure; 1 kPa for a rigid wall).
    ax : matplotlib Axes, optional
        Draw here (several walls can share one Axes); a new figure otherwise.
    n : int
        Number of points of the default range.
    label : str, optional
        Legend entry; defaults to the wall's registered name.
    rigid : bool
        Also draw the rigid-tube (generalized Hagen–Poiseuille) curve,
        ``q = rheology.flow_rate(a, dp / L)``, dashed grey, over the curve's pressure
        range plus 30 % (skipped for a rigid wall).
    color : matplotlib color, optional
        Colour of the curve and its limit lines; the Axes' colour cycle otherwise.
    outlet_pressure, coupler
        Passed to :func:`tubefsi.solve`.

    Draws the curve (one solve over the whole array of flow rates), the rigid
    reference, and, when finite, the maximum flow rate (dashed horizontal) and the
    largest possible pressure drop, limit pressure minus outlet pressure (dotted
    vertical), in the curve's colour.

    Returns
    -------
    matplotlib.axes.Axes
    """
    probe = solve(rheology, wall, tube, flow_rate=0.0, outlet_pressure=outlet_pressure, coupler=coupler)
    fluid, wall = probe.rheology, probe.wall
    if flow_rates is None:
        q, q_max = _default_flow_rates(probe, tube, _check_count("n", n), outlet_pressure)
    else:
        q = np.ravel(np.asarray(flow_rates, dtype=float))
        q_max = max_flow_rate(fluid, wall, tube, outlet_pressure=outlet_pressure)
    try:
        sol = solve(fluid, wall, tube, flow_rate=q, outlet_pressure=outlet_pressure, coupler=coupler)
    except (NoSteadyStateError, StretchRangeError) as exc:
        # near n = 1 the inlet stretch diverges so fast that the solver's range lies well below
        # q_max; a default range then stops at 90 % of what can be reached
        if flow_rates is not None or getattr(exc, "quantity", "flow_rate") != "flow_rate" or not exc.limit < q[-1]:
            raise
        q = np.linspace(0.0, 0.9 * exc.limit, q.size)
        sol = solve(fluid, wall, tube, flow_rate=q, outlet_pressure=outlet_pressure, coupler=coupler)
    label = _model_name(wall, "wall") if label is None else label

    ax = _new_axes(ax, (6.0, 4.2))
    (line,) = ax.plot(sol.pressure_drop, q, lw=2.0, label=label, color=color)
    line.sticky_edges.x.append(0.0)
    line.sticky_edges.y.append(0.0)
    color = line.get_color()
    if rigid and not wall.is_rigid:
        # a soft tube conducts far more than a rigid one: draw the reference over the soft
        # curve's pressure range (plus 30 %), so that it does not squeeze the curve it explains
        dp_top = 1.3 * float(np.max(sol.pressure_drop, initial=0.0))
        if dp_top > 0:
            dp_ref = np.linspace(0.0, dp_top, max(q.size, 50))
            q_ref = fluid.flow_rate(tube.radius, dp_ref / tube.length)
            ax.plot(dp_ref, q_ref, color="0.45", lw=1.2, ls="--", label="rigid tube")
    if math.isfinite(q_max):
        ax.axhline(q_max, color=color, lw=1.0, ls="--", label="_nolegend_")
        ax.annotate(f"$q_{{max}}$ = {_fmt(q_max, 'm³/s')}", xy=(0.0, q_max), xycoords=("axes fraction", "data"),
                    xytext=(4, -3), textcoords="offset points", ha="left", va="top", color=color, fontsize=8)
    lim = wall.limit_pressure(tube.reduced_thickness)
    if math.isfinite(lim):
        ax.axvline(lim - outlet_pressure, color=color, lw=1.0, ls=":", label="_nolegend_")
        ax.annotate(f"limit {_fmt(lim - outlet_pressure, 'Pa')}", xy=(lim - outlet_pressure, 0.4),
                    xycoords=("data", "axes fraction"), xytext=(3, 0), textcoords="offset points",
                    rotation=90, ha="left", va="bottom", color=color, fontsize=8)
    ax.set_xlabel(r"pressure drop $\Delta p$ (Pa)")
    ax.set_ylabel("flow rate $q$ (m³/s)")
    if not ax.get_title():
        ax.set_title(f"Flow curve: {_model_name(fluid, 'rheology')} fluid")
    ax.update_datalim([(0.0, 0.0)])       # from the origin, without freezing autoscaling
    ax.autoscale_view()
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False)
    return ax


# ---------------------------------------------------------------------------- profiles
def plot_profiles(solution, *, axes=None, n=200, max_loads=8):
    r"""Plot the pressure :math:`p(z)` and the radius :math:`R(z)/a` along the tube.

    Parameters
    ----------
    solution : Solution
        A single load gives one line per panel; a curve of loads gives one line per
        load for at most ``max_loads`` loads evenly spread over the flow rates,
        coloured by flow rate (with a colorbar).
    axes : pair of matplotlib Axes, optional
        Pressure and radius panels; a new two-panel figure otherwise.
    n : int
        Number of axial positions.
    max_loads : int
        Most lines per panel for a curve of loads.

    The pressure panel shows the wall's limit pressure (dashed) when it is finite,
    the radius panel the undeformed radius (dotted).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib as mpl

    n = _check_count("n", n)
    max_loads = _check_count("max_loads", max_loads, low=1)
    tube = solution.tube
    own = axes is None
    if own:
        fig, axes = _pyplot().subplots(2, 1, sharex=True, figsize=(6.4, 5.6), layout="constrained")
    else:
        axes = list(axes)
        if len(axes) != 2:
            raise InvalidParameterError("axes", "a pair of Axes (pressure, radius)", f"{len(axes)} Axes")
        fig = axes[0].figure
    ax_p, ax_r = axes
    z = np.linspace(0.0, tube.length, n)
    a = tube.radius

    single = np.size(solution.flow_rate) == 1
    if single:
        q = float(np.ravel(solution.flow_rate)[0])
        p = _along(solution.pressure, z, solution)[:, None]
        r = _along(solution.radius, z, solution)[:, None]
        colors = ["C0"]
    else:
        sub, qs = _subset(solution, max_loads)   # profiles cost one root solve per load and position
        p = np.asarray(sub.pressure(z[:, None]))
        r = np.asarray(sub.radius(z[:, None]))
        cmap = mpl.colormaps["viridis"]
        lo, hi = float(qs.min()), float(qs.max())
        norm = mpl.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
        colors = [cmap(0.9 * norm(v)) for v in qs]
    zz = z * _MM
    for j, c in enumerate(colors):
        ax_p.plot(zz, p[:, j], color=c, lw=1.8)
        ax_r.plot(zz, r[:, j] / a, color=c, lw=1.8)
    ax_r.axhline(1.0, color="0.5", lw=0.9, ls=":", label="undeformed")
    lim = solution.wall.limit_pressure(tube.reduced_thickness)
    if math.isfinite(lim):
        ax_p.axhline(lim, color="0.35", lw=1.0, ls="--", label="limit pressure")
        ax_p.legend(frameon=False, loc="lower left")

    ax_p.set_ylabel("pressure $p$ (Pa)")
    ax_r.set_ylabel("radius $R/a$")
    ax_r.set_xlabel("axial position $z$ (mm)")
    ax_p.set_xlim(0.0, tube.length * _MM)
    ax_p.set_ylim(bottom=min(0.0, float(np.min(p))))
    for axx in (ax_p, ax_r):
        axx.grid(True, alpha=0.25)
    wall_name = _model_name(solution.wall, "wall")
    fluid_name = _model_name(solution.rheology, "rheology")
    if single:
        ax_p.set_title(f"Pressure and radius along the tube, $q$ = {_fmt(q, 'm³/s')}, "
                       f"$\\Delta p$ = {_fmt(float(np.ravel(solution.pressure_drop)[0]), 'Pa')}", fontsize=10)
        ax_r.legend(frameon=False, loc="upper right")
    else:
        ax_p.set_title(f"Pressure and radius along the tube ({len(colors)} flow rates)", fontsize=10)
        sm = mpl.cm.ScalarMappable(norm=norm, cmap=mpl.colors.ListedColormap(cmap(np.linspace(0, 0.9, 256))))
        fig.colorbar(sm, ax=list(axes), label="flow rate $q$ (m³/s)", shrink=0.9)
        ax_r.legend(frameon=False, loc="upper right")
    if own:
        fig.suptitle(f"{fluid_name} fluid, {wall_name} wall", fontsize=11)
    return fig


# ---------------------------------------------------------------------------- deformed tube
def plot_deformed_tube(solution, *, ax=None, n=200, cmap="plasma"):
    r"""Draw the deformed tube in the :math:`(z, r)` plane, lumen coloured by pressure.

    The inner wall is drawn at :math:`\pm R(z)` over the undeformed radius (dotted),
    the lumen filled with the pressure field (a colorbar in Pa), and the wall itself
    shaded grey where its outer radius is known from incompressibility
    (:math:`R_o^2 - R^2 = (a+t)^2 - a^2`: hyperelastic, rigid, and
    :math:`\nu = 1/2` linear walls). Lengths are in millimetres; the radial axis is
    stretched (a slender tube drawn to scale would be a line).

    Parameters
    ----------
    solution : Solution
        A single-load solution.
    ax : matplotlib Axes, optional
    n : int
        Number of axial positions.
    cmap : str or Colormap

    Returns
    -------
    matplotlib.axes.Axes
    """
    n = _check_count("n", n)
    q, dp = _scalar_solution(solution, "plot_deformed_tube")
    tube = solution.tube
    a, t, L = tube.radius, tube.thickness, tube.length
    z = np.linspace(0.0, L, n)
    R = _along(solution.radius, z, solution)
    p = _along(solution.pressure, z, solution)

    ax = _new_axes(ax, (8.0, 3.6))
    zz, RR = z * _MM, R * _MM
    Z = np.repeat(zz[:, None], 2, axis=1)
    Y = RR[:, None] * np.array([-1.0, 1.0])
    P = np.repeat(p[:, None], 2, axis=1)
    mesh = ax.pcolormesh(Z, Y, P, shading="gouraud", cmap=cmap, rasterized=True)
    top = RR.max()
    if _incompressible(solution.wall):
        Ro = np.sqrt(R**2 + (a + t) ** 2 - a**2) * _MM
        ax.fill_between(zz, RR, Ro, color="0.78", lw=0, label="wall")
        ax.fill_between(zz, -Ro, -RR, color="0.78", lw=0)
        top = Ro.max()
    ax.plot(zz, RR, color="k", lw=1.4)
    ax.plot(zz, -RR, color="k", lw=1.4)
    ax.plot(zz, np.full_like(zz, a * _MM), color="0.3", lw=0.9, ls=":", label="undeformed lumen")
    ax.plot(zz, np.full_like(zz, -a * _MM), color="0.3", lw=0.9, ls=":", label="_nolegend_")
    ax.set_xlim(0.0, L * _MM)
    ax.set_ylim(-1.12 * top, 1.12 * top)
    ax.set_xlabel("axial position $z$ (mm)")
    ax.set_ylabel("radial position $r$ (mm)")
    ax.annotate("flow", xy=(0.16, 0.5), xytext=(0.03, 0.5), xycoords="axes fraction",
                ha="left", va="center", fontsize=9, color="w",
                arrowprops=dict(arrowstyle="-|>", color="w", lw=1.5))
    if not ax.get_title():
        ax.set_title(f"{_model_name(solution.wall, 'wall')} tube: $q$ = {_fmt(q, 'm³/s')}, "
                     f"$\\Delta p$ = {_fmt(dp, 'Pa')}, $R(0)/a$ = {R[0] / a:.3g}", fontsize=10)
    ax.figure.colorbar(mesh, ax=ax, label="pressure $p$ (Pa)", pad=0.02)
    ax.legend(frameon=False, loc="upper right", fontsize=8)
    return ax


# ---------------------------------------------------------------------------- velocity
def plot_velocity_profiles(solution, z_sections=None, *, ax=None, n=101):
    r"""Plot the axial velocity profile :math:`v(r)` across a few sections of the tube.

    Each profile spans the deformed lumen :math:`-R(z) \le r \le R(z)`, velocity on
    the horizontal axis (flow to the right), as in :func:`plot_deformed_tube`.

    Parameters
    ----------
    solution : Solution
        A single-load solution.
    z_sections : array_like, optional
        Axial positions (m) in ``[0, L]``; default: inlet, quarter points and outlet.
    ax : matplotlib Axes, optional
    n : int
        Points per profile.

    Returns
    -------
    matplotlib.axes.Axes
    """
    import matplotlib as mpl

    n = _check_count("n", n)
    q, _ = _scalar_solution(solution, "plot_velocity_profiles")
    L = solution.tube.length
    zs = np.linspace(0.0, L, 5) if z_sections is None else np.ravel(np.asarray(z_sections, dtype=float))
    if zs.size == 0:
        raise InvalidParameterError("z_sections", f"non-empty positions in [0, {L:g}] (m)", z_sections)
    R = _along(solution.radius, zs, solution)
    ax = _new_axes(ax, (6.0, 4.2))
    cmap = mpl.colormaps["viridis"]
    s = np.linspace(-1.0, 1.0, n)
    for k, (zk, Rk) in enumerate(zip(zs, R)):
        r = np.abs(s) * Rk
        v = _along(lambda rr: solution.velocity(np.minimum(rr, Rk), zk), r, solution)
        frac = 0.0 if zs.size == 1 else k / (zs.size - 1)
        ax.plot(v * _MM, s * Rk * _MM, color=cmap(0.9 * frac), lw=1.8, label=f"z = {zk * _MM:.3g} mm")
    ax.set_xlabel("axial velocity $v$ (mm/s)")
    ax.set_ylabel("radial position $r$ (mm)")
    ax.set_xlim(left=0.0)
    if not ax.get_title():
        ax.set_title(f"Velocity profiles, $q$ = {_fmt(q, 'm³/s')}", fontsize=10)
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False, fontsize=8, loc="upper right")
    return ax


# ---------------------------------------------------------------------------- networks
def plot_network(result, *, positions=None, ax=None, cmap="viridis", max_width=8.0, layout_seed=0):
    r"""Draw a solved network: nodes coloured by pressure, each tube a segment coloured by its
    mean pressure and as wide as its mean deformed inner radius.

    Parameters
    ----------
    result : NetworkSolution
        What :meth:`tubefsi.Network.solve` returns.
    positions : mapping node -> (x, y), optional
        Node coordinates; by default those of :meth:`~tubefsi.Network.set_position` (or the
        ``pos`` node attribute of a networkx graph), else a networkx spring layout (seeded by
        ``layout_seed``; needs networkx).
    ax : matplotlib Axes, optional
    cmap : str or Colormap
    max_width : float
        Line width (points) of the widest tube; the others in proportion to their radius.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    nodes = result.nodes
    pos = dict(result.net.positions if positions is None else positions)
    if any(node not in pos for node in nodes):
        try:
            import networkx as nx
        except ImportError:
            raise InvalidParameterError("positions", "(x, y) for every node", None,
                                        "give positions= or set_position(), or install networkx for a layout") from None
        pos = {**nx.spring_layout(result.net.to_networkx().to_undirected(as_view=True), seed=layout_seed), **pos}
    table = result.tube_table()
    p = result.pressure
    xy = np.array([[pos[u], pos[v]] for u, v in zip(table["u"], table["v"])], dtype=float)
    radius = 0.5 * (np.asarray(table["radius_u"]) + np.asarray(table["radius_v"]))
    widths = max_width * radius / radius.max()
    mean_p = 0.5 * (np.asarray(table["pressure_u"]) + np.asarray(table["pressure_v"]))
    values = np.array([p[n] for n in nodes])
    norm = Normalize(vmin=float(values.min()), vmax=float(values.max()) if values.max() > values.min() else
                     float(values.min()) + 1.0)
    ax = _new_axes(ax, (7.0, 5.0))
    lines = LineCollection(xy, linewidths=np.maximum(widths, 0.4), cmap=cmap, norm=norm, capstyle="round", zorder=1)
    lines.set_array(mean_p)
    ax.add_collection(lines)
    pts = np.array([pos[n] for n in nodes], dtype=float)
    ax.scatter(pts[:, 0], pts[:, 1], c=values, cmap=cmap, norm=norm, s=14, edgecolors="k", linewidths=0.4, zorder=2)
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_axis_off()
    ax.figure.colorbar(lines, ax=ax, label="pressure $p$ (Pa)", shrink=0.8)
    if not ax.get_title():
        ax.set_title(f"{len(nodes)} nodes, {len(table['name'])} tubes; width ~ deformed radius "
                     f"(widest {_fmt(float(radius.max()) * _MM, 'mm')})", fontsize=10)
    return ax
