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
* :func:`plot_network` — a solved :class:`~tubefsi.Network`, tubes coloured by pressure, flow
  rate, strain or wall shear stress and as wide as their deformed radius (Axes).

``WallModel.plot`` and ``Solution.plot`` are shortcuts for :func:`plot_tube_law`
and :func:`plot_profiles`. Arguments are SI; each axis shows its quantity in the unit that
suits its data (flow rates in nL/min, µL/min or mL/min, pressures in Pa or kPa, lengths in µm
or mm, velocities in mm/s, ...), so that no tick label needs an offset such as "1e-8"; the
axis label names the unit, and curves drawn later onto the same Axes keep it.

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
from ._keywords import checked_keywords
from .errors import InvalidParameterError, NoSteadyStateError, StretchRangeError, TubefsiError
from .network_io import tree_layout
from .solve import max_flow_rate, solve, solve_unchecked
from .validity import SLENDERNESS
from .walls.hyperelastic import HyperelasticWall

__all__ = [
    "plot_tube_law",
    "plot_flow_curve",
    "plot_profiles",
    "plot_deformed_tube",
    "plot_velocity_profiles",
    "plot_network",
]

_TANGENT_GID = "tubefsi-small-strain-tangent"

# Display units: (symbol, size in SI), smallest first. An axis shows its quantity in the largest
# unit not larger than the data's magnitude, so that tick labels need no offset ("1e-8") and read
# as numbers of the scale the field uses (µL/min, kPa, µm).
_UNITS = {
    "flow_rate": (("pL/min", 1e-15 / 60), ("nL/min", 1e-12 / 60), ("µL/min", 1e-9 / 60),
                  ("mL/min", 1e-6 / 60), ("L/min", 1e-3 / 60)),
    "pressure": (("mPa", 1e-3), ("Pa", 1.0), ("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9)),
    "length": (("nm", 1e-9), ("µm", 1e-6), ("mm", 1e-3), ("m", 1.0)),
    "velocity": (("µm/s", 1e-6), ("mm/s", 1e-3), ("m/s", 1.0)),
}


def _unit(kind, magnitude):
    """``(symbol, size)`` of the display unit of ``kind`` for data of largest size ``magnitude`` (SI)."""
    units = _UNITS[kind]
    m = abs(float(magnitude)) if np.isfinite(magnitude) else 0.0
    if m == 0.0:
        return units[1] if kind != "length" else units[2]
    best = units[0]
    for unit in units:
        if unit[1] <= m * (1 + 1e-12):
            best = unit
    return best


def _axes_unit(ax, axis, kind, magnitude):
    """The unit of an Axes' ``axis`` ("x"/"y"): chosen by the first call, kept by later ones, so
    that curves drawn onto one Axes share its scale."""
    store = ax.__dict__.setdefault("_tubefsi_units", {})
    if axis not in store:
        store[axis] = _unit(kind, magnitude)
    return store[axis]


def _scaled_formatter(size):
    """A tick formatter showing ``value / size`` (a colour bar kept in SI, read in a display unit)."""
    from matplotlib.ticker import FuncFormatter

    return FuncFormatter(lambda v, _pos: f"{v / size:g}")


def _fmt_q(q) -> str:
    """A flow rate (m^3/s) in its display unit, for titles and legends."""
    sym, size = _unit("flow_rate", q)
    return _fmt(q / size, sym)


def _fmt_len(x) -> str:
    """A length (m) in its display unit."""
    sym, size = _unit("length", x)
    return _fmt(x / size, sym)


def _fmt_p(p) -> str:
    """A pressure (Pa) in its display unit."""
    sym, size = _unit("pressure", p)
    return _fmt(p / size, sym)


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
    sub = attrs.evolve(solution, state=type(state)(*(np.ravel(np.asarray(value))[pick] for value in state)),
                       scalar=False)
    return sub, q[pick]


# ---------------------------------------------------------------------------- tube law
def _pressure_scale(ax, wall, tb, normalize, scale_name, magnitude):
    """``(scale in Pa, ylabel, unit symbol or None if dimensionless)`` of a tube-law Axes: one scale
    per Axes, fixed by its first wall."""
    store = ax.__dict__.setdefault("_tubefsi_units", {})
    if "tube_law" in store:
        return store["tube_law"]
    if wall.is_rigid and normalize is True:
        raise InvalidParameterError("normalize", "False or a pressure scale, for a rigid wall first on an Axes",
                                    True, "a rigid wall has no small-strain modulus to normalize by")
    if normalize is False:
        sym, size = _unit("pressure", magnitude)
        scale = (size, f"transmural pressure $p$ ({sym})", sym)
    elif normalize is True:
        k0 = wall.small_strain_modulus(tb)
        name = scale_name or "k_0"
        scale = (k0, rf"$p\,/\,{name}$,  ${name}$ = {_fmt_p(k0)} ($dp/d\lambda$ at $\lambda = 1$ of "
                     f"{_model_name(wall, 'wall')})", None)
    else:
        try:
            value = float(normalize)
        except (TypeError, ValueError):
            raise InvalidParameterError("normalize", "True, False or a pressure scale in (0, inf) Pa",
                                        normalize) from None
        if not (math.isfinite(value) and value > 0):
            raise InvalidParameterError("normalize", "True, False or a pressure scale in (0, inf) Pa", normalize)
        name = scale_name or "p_0"
        scale = (value, rf"$p\,/\,{name}$,  ${name}$ = {_fmt_p(value)}", None)
    store["tube_law"] = scale
    return scale


#: The default tube-law plot ends at this stretch, or earlier where the law stiffens: where its
#: pressure reaches ``_STIFFENING_SPAN`` times its small-strain modulus (an exponential law there
#: is already far beyond any tissue's range; drawn further, its physiological part is a flat line).
_DEFAULT_MAX_STRETCH = 3.0
_STIFFENING_SPAN = 20.0
#: A finite limit pressure is drawn (tube law, flow curve) only when it lies within this multiple
#: of the largest pressure drawn on the axes: a stiffening law's "limit" is where double precision ends, not
#: a physical bound, and drawn it would flatten the curve onto the axis.
_LIMIT_IN_VIEW = 3.0


def _default_max_stretch(wall, tb):
    """The physical end of a tube-law plot: 3, or where the pressure reaches 20 small-strain moduli."""
    k0 = float(wall.small_strain_modulus(tb))
    target = _STIFFENING_SPAN * k0
    lim = float(wall.limit_pressure(tb))
    if not (math.isfinite(target) and target > 0) or target >= lim:
        return _DEFAULT_MAX_STRETCH
    try:
        lam = float(wall.stretch(target, tb))
    except TubefsiError:          # beyond the wall's range: the default
        return _DEFAULT_MAX_STRETCH
    return min(_DEFAULT_MAX_STRETCH, lam) if math.isfinite(lam) and lam > 1.0 else _DEFAULT_MAX_STRETCH


def _limit_in_view(limit, top) -> bool:
    return math.isfinite(limit) and limit <= _LIMIT_IN_VIEW * top


def plot_tube_law(wall, reduced_thickness, *, ax=None, max_stretch=None, normalize=False, scale_name=None,
                  label=None, color=None):
    r"""Plot a wall's tube law: transmural pressure :math:`p` against hoop stretch :math:`\lambda = R/a`.

    Parameters
    ----------
    wall : WallModel
    reduced_thickness : float
        :math:`\bar t = t/a`.
    ax : matplotlib Axes, optional
        Draw here (several walls can share one Axes); a new figure otherwise.
    max_stretch : float, optional
        Right end of the stretch axis (> 1); clipped just below the wall's own
        maximum stretch, if it has one. By default 3, or less for a law that stiffens: the
        stretch where its pressure reaches 20 times its small-strain modulus :math:`k_0`.
    normalize : bool or float
        The pressure scale, **one per Axes** (the first wall drawn on an Axes fixes it, and
        the walls drawn after it share it, so their curves compare): ``False`` (default)
        pressures in Pa or kPa, whichever reads best; ``True`` divided by the small-strain
        modulus :math:`k_0 = dp/d\lambda|_{\lambda=1}` *of the first wall* (which then starts
        with slope 1); a number divides by that pressure (Pa), e.g. the material's shear
        modulus. The y label states the scale and its value.
    scale_name : str, optional
        TeX symbol of the scale in the y label (``"k_0"`` for ``True``, ``"p_0"`` for a number;
        e.g. ``r"\mu"``).
    label : str, optional
        Legend entry; defaults to the wall's registered name.
    color : matplotlib color, optional
        Colour of the curve (and its limit line); the Axes' colour cycle otherwise.

    Notes
    -----
    Draws the tube law (solid), its linear small-strain tangent :math:`k_0(\lambda-1)`
    (faint, in the curve's colour; one legend entry per Axes) and, when finite and within three
    times the highest pressure drawn, the limit pressure as a dashed horizontal line in the
    curve's colour, labelled in the axis' own scale (the "limit" of a stiffening law is where
    double precision ends, astronomically high: not drawn). A rigid wall is the vertical line :math:`\lambda = 1` on a pressure axis in
    pascals, and is not drawn on a dimensionless one (it has no small-strain modulus; its
    law is :math:`\lambda = 1` at every pressure).

    Returns
    -------
    matplotlib.axes.Axes
    """
    tb = wall._check_thickness(reduced_thickness)
    if max_stretch is None:
        max_stretch = _DEFAULT_MAX_STRETCH if wall.is_rigid else _default_max_stretch(wall, tb)
    try:
        max_stretch = float(max_stretch)
    except (TypeError, ValueError):
        raise InvalidParameterError("max_stretch", "(1, inf)", max_stretch) from None
    if not (math.isfinite(max_stretch) and max_stretch > 1.0):
        raise InvalidParameterError("max_stretch", "(1, inf)", max_stretch)
    label = _model_name(wall, "wall") if label is None else label
    ax = _new_axes(ax, (6.0, 4.2))
    if not ax.get_title():
        ax.set_title(f"Tube law, $t/a$ = {tb:.3g}")
    ax.set_xlabel(r"hoop stretch $\lambda = R/a$")
    if wall.is_rigid:
        scale, ylabel, unit = _pressure_scale(ax, wall, tb, normalize, scale_name, 1e3)
        ax.set_ylabel(ylabel)
        if unit is not None:
            ax.axvline(1.0, color="0.15" if color is None else color, lw=2.0, label=label)
        # keep the stretch axis as wide as for the other walls, without freezing autoscaling
        ax.update_datalim([(1.0, 0.0), (max_stretch, 0.0)], updatey=False)
        ax.autoscale_view()
        ax.grid(True, alpha=0.25)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(frameon=False)
        return ax

    lam_cap = wall.max_stretch(tb)
    hi = max_stretch if not math.isfinite(lam_cap) else min(max_stretch, 1.0 + (lam_cap - 1.0) * (1 - 1e-6))
    lam = np.linspace(1.0, hi, 400)
    p = np.asarray(wall.pressure(lam, tb), dtype=float)
    k0 = wall.small_strain_modulus(tb)
    scale, ylabel, unit = _pressure_scale(ax, wall, tb, normalize, scale_name, float(np.max(p)))
    ax.set_ylabel(ylabel)
    (line,) = ax.plot(lam, p / scale, lw=2.0, label=label, color=color)
    line.sticky_edges.y.append(0.0)   # pressures start at 0, even on a shared Axes
    color = line.get_color()

    # the small-strain tangent, drawn only as high as the curve goes (so it does not set the scale)
    lim = wall.limit_pressure(tb)
    shown = _limit_in_view(lim, float(np.max(p)))
    top = max(float(p[-1]), lim if shown else 0.0) * 1.08
    lam_t = np.linspace(1.0, min(hi, 1.0 + top / k0), 50)
    first = not any(ln.get_gid() == _TANGENT_GID for ln in ax.get_lines())
    ax.plot(lam_t, k0 * (lam_t - 1.0) / scale, color=color, lw=1.0, alpha=0.4, ls="-",
            label="small-strain tangents" if first else "_nolegend_", gid=_TANGENT_GID)

    if shown:
        ax.axhline(lim / scale, color=color, lw=1.0, ls="--", label="_nolegend_")
        text = f"limit {lim / scale:.3g}" if unit is None else f"limit {_fmt_p(lim)}"
        ax.annotate(text, xy=(hi, lim / scale), xytext=(-4, 3),
                    textcoords="offset points", ha="right", va="bottom", color=color, fontsize=8)
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False)
    return ax


# ---------------------------------------------------------------------------- flow curve
def _valid_flow_rate(fluid, wall, tube, outlet_pressure, coupler):
    """The flow rate at which the deformed tube stops being slender (``docs/scope.md``): the inlet
    radius reaches :data:`tubefsi.validity.SLENDERNESS` times the length; ``inf`` if that is beyond
    the wall's range or limit pressure."""
    tb = tube.reduced_thickness
    # a hair inside the limit, so that this probe's own solve does not warn
    lam = 1.0 + (1.0 - 1e-6) * (SLENDERNESS * tube.length / tube.radius - 1.0)
    if wall.is_rigid or not lam < wall.max_stretch(tb):
        return math.inf
    try:
        dp = float(wall.pressure(lam, tb)) - outlet_pressure
    except (TypeError, ValueError):      # array-valued wall parameters: no single limit
        return math.inf
    if not (math.isfinite(dp) and dp > 0):
        return math.inf
    lim = wall.limit_pressure(tb)
    if math.isfinite(lim) and dp >= lim - outlet_pressure:
        return math.inf
    try:
        # a probe: the curve drawn is checked, not this point
        return float(solve_unchecked(fluid, wall, tube, pressure_drop=dp, outlet_pressure=outlet_pressure,
                                     coupler=coupler).flow_rate)
    except (NoSteadyStateError, StretchRangeError):
        return math.inf


def _default_flow_rates(scene_sol, tube, n, outlet_pressure, coupler="auto"):
    """``0..0.9 q_max`` if the maximum flow rate is finite, else a rigid-tube estimate; either
    stopped at 99 % of the flow rate where the tube stops being slender (:func:`_valid_flow_rate`).

    The estimate is the rigid-tube flow rate at a pressure drop of the wall's
    small-strain modulus (the pressure that would double the radius by the linear
    law), capped at 90 % of the limit pressure; 1 kPa for a rigid wall.
    """
    fluid, wall = scene_sol.rheology, scene_sol.wall
    q_max = max_flow_rate(fluid, wall, tube, outlet_pressure=outlet_pressure)
    if math.isfinite(q_max):
        q_hi = 0.9 * q_max
    else:
        tb = tube.reduced_thickness
        if wall.is_rigid:
            dp = 1e3
        else:
            dp = wall.small_strain_modulus(tb)
            lim = wall.limit_pressure(tb)
            if math.isfinite(lim):
                dp = min(dp, 0.9 * (lim - outlet_pressure))
        q_hi = float(fluid.flow_rate(tube.radius, dp / tube.length))
    q_hi = min(q_hi, 0.99 * _valid_flow_rate(fluid, wall, tube, outlet_pressure, coupler))
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
        pressure; 1 kPa for a rigid wall); in either case stopped at 99 % of the flow rate
        where the deformed tube stops being slender (inlet radius :math:`R_{in} = 0.1 L`,
        ``docs/scope.md``), so that the default curve of a hyperelastic wall draws without a
        :class:`~tubefsi.ModelValidityWarning` (a linear wall still warns once its inlet strain
        passes its calibrated 5 %).
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

    Notes
    -----
    Draws the curve (one solve over the whole array of flow rates), the rigid
    reference, and, when finite, the maximum flow rate (dashed horizontal) and, within three
    times the largest drop drawn, the largest possible pressure drop, limit pressure minus
    outlet pressure (dotted vertical), in the curve's colour. The axes are in the units that suit the first curve
    drawn on them (flow rates in nL/min, µL/min or mL/min, pressures in Pa or kPa; the labels
    say which), kept for the curves drawn after it.

    Returns
    -------
    matplotlib.axes.Axes
    """
    probe = solve(rheology, wall, tube, flow_rate=0.0, outlet_pressure=outlet_pressure, coupler=coupler)
    fluid, wall = probe.rheology, probe.wall
    if flow_rates is None:
        q, q_max = _default_flow_rates(probe, tube, _check_count("n", n), outlet_pressure, coupler)
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
    dp = np.asarray(sol.pressure_drop, dtype=float)

    ax = _new_axes(ax, (6.0, 4.2))
    p_sym, p_unit = _axes_unit(ax, "x", "pressure", np.max(dp, initial=0.0))
    q_sym, q_unit = _axes_unit(ax, "y", "flow_rate", np.max(q, initial=0.0))
    (line,) = ax.plot(dp / p_unit, q / q_unit, lw=2.0, label=label, color=color)
    line.sticky_edges.x.append(0.0)
    line.sticky_edges.y.append(0.0)
    color = line.get_color()
    if rigid and not wall.is_rigid:
        # a soft tube conducts far more than a rigid one: draw the reference over the soft
        # curve's pressure range (plus 30 %), so that it does not squeeze the curve it explains
        dp_top = 1.3 * float(np.max(dp, initial=0.0))
        if dp_top > 0:
            dp_ref = np.linspace(0.0, dp_top, max(q.size, 50))
            q_ref = fluid.flow_rate(tube.radius, dp_ref / tube.length)
            ax.plot(dp_ref / p_unit, q_ref / q_unit, color="0.45", lw=1.2, ls="--", label="rigid tube")
    if math.isfinite(q_max):
        ax.axhline(q_max / q_unit, color=color, lw=1.0, ls="--", label="_nolegend_")
        ax.annotate(f"$q_{{max}}$ = {_fmt(q_max / q_unit, q_sym)}", xy=(0.0, q_max / q_unit),
                    xycoords=("axes fraction", "data"), xytext=(4, -3), textcoords="offset points",
                    ha="left", va="top", color=color, fontsize=8)
    lim = wall.limit_pressure(tube.reduced_thickness)
    # in view of every curve on these axes (a shared axis keeps the first curve's range)
    drawn = max(float(np.max(dp, initial=0.0)), float(ax.dataLim.x1) * p_unit if ax.dataLim.x1 > 0 else 0.0)
    if _limit_in_view(lim - outlet_pressure, drawn):
        x_lim = (lim - outlet_pressure) / p_unit
        ax.axvline(x_lim, color=color, lw=1.0, ls=":", label="_nolegend_")
        ax.annotate(f"limit {_fmt_p(lim - outlet_pressure)}", xy=(x_lim, 0.4),
                    xycoords=("data", "axes fraction"), xytext=(3, 0), textcoords="offset points",
                    rotation=90, ha="left", va="bottom", color=color, fontsize=8)
    ax.set_xlabel(rf"pressure drop $\Delta p$ ({p_sym})")
    ax.set_ylabel(f"flow rate $q$ ({q_sym})")
    if not ax.get_title():
        ax.set_title(f"Flow curve: {_model_name(fluid, 'rheology')} fluid")
    ax.update_datalim([(0.0, 0.0)])       # from the origin, without freezing autoscaling
    ax.autoscale_view()
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False)
    return ax


# ---------------------------------------------------------------------------- profiles
#: The limit pressure is drawn on a profile's pressure axis only if it lies below this multiple
#: of the largest pressure drawn; higher, it is stated at the top of the axis instead (drawn,
#: it would squeeze the profiles into the bottom of the panel).
_LIMIT_SHOWN_BELOW = 1.25


def plot_profiles(solution, *, axes=None, n=200, max_loads=8):
    r"""Plot the pressure :math:`p(z)` and the radius :math:`R(z)/a` along the tube (for a tapered
    or graded tube, ``docs/graded.md``, the radius :math:`R(z)` and :math:`a(z)` in mm).

    Parameters
    ----------
    solution : Solution
        A single load gives one line per panel; a curve of loads gives one line per
        load for at most ``max_loads`` loads evenly spread over the flow rates, each in its
        own colour, with a legend of their flow rates.
    axes : pair of matplotlib Axes, optional
        Pressure and radius panels; a new two-panel figure otherwise.
    n : int
        Number of axial positions.
    max_loads : int
        Most lines per panel for a curve of loads.

    Notes
    -----
    The radius panel shows the undeformed radius :math:`R/a = 1` (black dashed, drawn over the
    profiles: a load of zero flow rate lies on it). The pressure panel shows the wall's limit
    pressure (dashed) when it is finite and within 1.25 times the largest pressure drawn;
    a higher one is stated in a note at the top of the panel, so that the profiles keep the
    whole axis. Pressures are in Pa or kPa and positions in mm or µm, whichever reads best
    (the labels say which).

    Returns
    -------
    matplotlib.figure.Figure
    """
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
        qs = np.ravel(np.asarray(solution.flow_rate, dtype=float))[:1]
        p = _along(solution.pressure, z, solution)[:, None]
        r = _along(solution.radius, z, solution)[:, None]
        colors = ["C0"]
    else:
        import matplotlib as mpl

        sub, qs = _subset(solution, max_loads)   # profiles cost one root solve per load and position
        p = np.asarray(sub.pressure(z[:, None]))
        r = np.asarray(sub.radius(z[:, None]))
        cmap = mpl.colormaps["viridis"]
        colors = [cmap(0.9 * k / max(len(qs) - 1, 1)) for k in range(len(qs))]   # one colour per load
    graded = solution.scene.graded       # a taper or stenosis: R(z) and a(z) in length units, not R/a
    if graded:                           # the limit pressure of the inlet section
        inlet = solution.scene.uniform_at(0.0)
        lim = inlet.wall.limit_pressure(inlet.tb)
        lim = float(np.min(lim)) if np.ndim(lim) else lim
    else:
        lim = solution.wall.limit_pressure(tube.reduced_thickness)
    p_top = float(np.max(p, initial=0.0))
    show_limit = math.isfinite(lim) and lim <= _LIMIT_SHOWN_BELOW * max(p_top, 0.0) and p_top > 0
    z_sym, z_unit = _axes_unit(ax_r, "x", "length", tube.length)
    p_sym, p_unit = _axes_unit(ax_p, "y", "pressure", max(p_top, lim if show_limit else 0.0))
    q_sym, q_unit = _unit("flow_rate", float(np.max(qs, initial=0.0)))
    zz = z / z_unit
    if graded:
        r_sym, r_unit = _axes_unit(ax_r, "y", "length", float(np.max(r, initial=0.0)))
    scale = 1.0 / r_unit if graded else 1.0 / a
    for j, c in enumerate(colors):
        entry = f"{qs[j] / q_unit:.3g}"
        ax_p.plot(zz, p[:, j] / p_unit, color=c, lw=1.8, label=entry)
        ax_r.plot(zz, r[:, j] * scale, color=c, lw=1.8, label="_nolegend_")
    if graded:
        ax_r.plot(zz, np.broadcast_to(tube.at(z)[0], z.shape) * scale, color="k", lw=1.2, ls=(0, (4, 3)), zorder=3,
                  label="undeformed")
    else:
        ax_r.axhline(1.0, color="k", lw=1.2, ls=(0, (4, 3)), zorder=3, label="undeformed")
    if show_limit:
        ax_p.axhline(lim / p_unit, color="0.35", lw=1.0, ls="--", label="limit pressure")
    elif math.isfinite(lim):
        ax_p.annotate(f"limit pressure {_fmt_p(lim)} (above the axis)", xy=(0.99, 0.98),
                      xycoords="axes fraction", ha="right", va="top", fontsize=8, color="0.35")

    ax_p.set_ylabel(f"pressure $p$ ({p_sym})")
    ax_r.set_ylabel(f"radius $R$ ({r_sym})" if graded else "radius $R/a$")
    ax_r.set_xlabel(f"axial position $z$ ({z_sym})")
    ax_p.set_xlim(0.0, tube.length / z_unit)
    ax_p.set_ylim(bottom=min(0.0, float(np.min(p)) / p_unit))
    if not graded:
        ax_r.set_ylim(bottom=min(0.95, float(np.min(r)) / a - 0.02))
    for axx in (ax_p, ax_r):
        axx.grid(True, alpha=0.25)
    wall_name = _model_name(solution.wall, "wall")
    fluid_name = _model_name(solution.rheology, "rheology")
    lines = ax_p.get_lines()
    if single:
        ax_p.set_title(f"Pressure and radius along the tube, $q$ = {_fmt_q(float(qs[0]))}, "
                       f"$\\Delta p$ = {_fmt_p(float(np.ravel(solution.pressure_drop)[0]))}", fontsize=10)
        if show_limit:
            ax_p.legend([lines[-1]], ["limit pressure"], frameon=False, loc="lower left")
    else:
        ax_p.set_title(f"Pressure and radius along the tube ({len(colors)} flow rates)", fontsize=10)
        # a discrete legend, one entry per drawn flow rate (and the limit pressure)
        handles = lines[:len(colors)] + (lines[-1:] if show_limit else [])
        labels = [h.get_label() for h in handles]
        options = dict(title=f"flow rate $q$\n({q_sym})", frameon=False, fontsize=8, title_fontsize=9)
        if own:
            fig.legend(handles, labels, loc="outside right upper", **options)
        else:
            ax_p.legend(handles, labels, loc="lower left", **options)
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
    z_sym, z_unit = _axes_unit(ax, "x", "length", L)
    r_sym, r_unit = _axes_unit(ax, "y", "length", float(np.max(R)) + t)
    zz, RR = z / z_unit, R / r_unit
    Z = np.repeat(zz[:, None], 2, axis=1)
    Y = RR[:, None] * np.array([-1.0, 1.0])
    P = np.repeat(p[:, None], 2, axis=1)
    mesh = ax.pcolormesh(Z, Y, P, shading="gouraud", cmap=cmap, rasterized=True)
    top = RR.max()
    if _incompressible(solution.wall):
        Ro = np.sqrt(R**2 + (a + t) ** 2 - a**2) / r_unit
        ax.fill_between(zz, RR, Ro, color="0.78", lw=0, label="wall")
        ax.fill_between(zz, -Ro, -RR, color="0.78", lw=0)
        top = Ro.max()
    ax.plot(zz, RR, color="k", lw=1.4)
    ax.plot(zz, -RR, color="k", lw=1.4)
    ax.plot(zz, np.full_like(zz, a / r_unit), color="0.3", lw=0.9, ls=":", label="undeformed lumen")
    ax.plot(zz, np.full_like(zz, -a / r_unit), color="0.3", lw=0.9, ls=":", label="_nolegend_")
    ax.set_xlim(0.0, L / z_unit)
    ax.set_ylim(-1.12 * top, 1.12 * top)
    ax.set_xlabel(f"axial position $z$ ({z_sym})")
    ax.set_ylabel(f"radial position $r$ ({r_sym})")
    ax.annotate("flow", xy=(0.16, 0.5), xytext=(0.03, 0.5), xycoords="axes fraction",
                ha="left", va="center", fontsize=9, color="w",
                arrowprops=dict(arrowstyle="-|>", color="w", lw=1.5))
    if not ax.get_title():
        ax.set_title(f"{_model_name(solution.wall, 'wall')} tube: $q$ = {_fmt_q(q)}, "
                     f"$\\Delta p$ = {_fmt_p(dp)}, $R(0)/a$ = {R[0] / a:.3g}", fontsize=10)
    bar = ax.figure.colorbar(mesh, ax=ax, label="pressure $p$ (Pa)", pad=0.02)
    p_sym, p_unit = _unit("pressure", float(np.max(p)))
    if p_unit != 1.0:   # the mesh stays in Pa (its clim is the pressure range); the ticks read in kPa
        bar.formatter = _scaled_formatter(p_unit)
        bar.set_label(f"pressure $p$ ({p_sym})")
        bar.update_ticks()
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
    z_sym, z_unit = _unit("length", L)
    r_sym, r_unit = _axes_unit(ax, "y", "length", float(np.max(R)))
    v_sym, v_unit = _axes_unit(ax, "x", "velocity", 2.0 * q / (np.pi * float(np.min(R)) ** 2))
    cmap = mpl.colormaps["viridis"]
    s = np.linspace(-1.0, 1.0, n)
    for k, (zk, Rk) in enumerate(zip(zs, R)):
        r = np.abs(s) * Rk
        v = _along(lambda rr: solution.velocity(np.minimum(rr, Rk), zk), r, solution)
        frac = 0.0 if zs.size == 1 else k / (zs.size - 1)
        ax.plot(v / v_unit, s * Rk / r_unit, color=cmap(0.9 * frac), lw=1.8,
                label=f"z = {zk / z_unit:.3g} {z_sym}")
    ax.set_xlabel(f"axial velocity $v$ ({v_sym})")
    ax.set_ylabel(f"radial position $r$ ({r_sym})")
    ax.set_xlim(left=0.0)
    if not ax.get_title():
        ax.set_title(f"Velocity profiles, $q$ = {_fmt_q(q)}", fontsize=10)
    ax.grid(True, alpha=0.25)
    ax.legend(frameon=False, fontsize=8, loc="upper right")
    return ax


# ---------------------------------------------------------------------------- networks
#: what plot_network can colour the tubes by: (label, display unit kind or None, the value per tube)
_NETWORK_COLOURS = {
    "pressure": ("mean pressure $p$", "pressure",
                 lambda r: 0.5 * (r.pressures[r.U] + r.pressures[r.V])),
    "flow_rate": ("flow rate $|q|$", "flow_rate", lambda r: np.abs(r.flow_rates)),
    "strain": ("largest hoop strain $R/a - 1$", None, lambda r: np.maximum(r.strain_u, r.strain_v)),
    "wall_shear_stress": (r"largest wall shear stress $\tau_w$", "pressure",
                          lambda r: np.maximum(r.wall_shear_stress_u, r.wall_shear_stress_v)),
}


@checked_keywords
def plot_network(result, *, color="pressure", positions=None, layout="tree", ax=None, cmap="viridis",
                 max_width=8.0, layout_seed=0):
    r"""Draw a solved network: each tube a segment coloured by ``color`` and as wide as its mean
    deformed inner radius; the nodes coloured by their pressure when ``color="pressure"``.

    Parameters
    ----------
    result : NetworkSolution
        What :meth:`tubefsi.Network.solve` returns.
    color : {"pressure", "flow_rate", "strain", "wall_shear_stress"}
        What colours the tubes: the mean of their two end pressures, the magnitude of their
        flow rate, the larger hoop strain :math:`R/a - 1` of their two ends, or the larger wall
        shear stress of their two ends. The colour bar shows it in a display unit (kPa, mL/min,
        ...).
    positions : mapping node -> (x, y), optional
        Node coordinates (m; a point (x, y, z) is drawn at (x, y)); by default those of :meth:`~tubefsi.Network.set_position` (or the
        ``pos`` node attribute of a networkx graph), else the ``layout``.
    layout : {"tree", "spring"}
        Where nodes have no position: ``"tree"``, :func:`tubefsi.network_io.tree_layout`
        (x the distance from the inlet along the tubes); ``"spring"``, a networkx spring layout
        seeded by ``layout_seed`` (needs networkx).
    ax : matplotlib Axes, optional
    cmap : str or Colormap
        A matplotlib colormap or its registered name.
    max_width : float
        Line width (points, > 0) of the widest tube; the others in proportion to their radius.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    if color not in _NETWORK_COLOURS:
        raise InvalidParameterError("color", f"one of {sorted(_NETWORK_COLOURS)}", color)
    if layout not in ("tree", "spring"):
        raise InvalidParameterError("layout", "'tree' or 'spring'", layout)
    import matplotlib
    from matplotlib.colors import Colormap

    if not isinstance(cmap, Colormap) and not (isinstance(cmap, str) and cmap in matplotlib.colormaps):
        raise InvalidParameterError("cmap", "a matplotlib Colormap or a registered colormap name such as 'viridis'",
                                    cmap)
    width = np.asarray(max_width, dtype=float) if isinstance(max_width, (int, float, np.number)) else None
    if width is None or isinstance(max_width, bool) or not (np.isfinite(width) and width > 0):
        raise InvalidParameterError("max_width", "(0, inf) points", max_width)
    if positions is not None and not hasattr(positions, "keys"):
        raise InvalidParameterError("positions", "a mapping node -> (x, y) or (x, y, z) (m)", positions)
    nodes = result.nodes
    pos = dict(result.net.positions if positions is None else positions)
    if any(node not in pos for node in nodes):
        if layout == "tree":
            pos = {**tree_layout(result.net), **pos}
        else:
            try:
                import networkx as nx
            except ImportError:
                raise InvalidParameterError("layout", "'tree', or 'spring' with networkx installed", layout,
                                            "give positions= or set_position(), or install networkx") from None
            pos = {**nx.spring_layout(result.net.to_networkx().to_undirected(as_view=True), seed=layout_seed), **pos}
    pts = np.empty((len(nodes), 2))
    for i, node in enumerate(nodes):
        try:
            point = np.asarray(pos[node], dtype=float)
        except (TypeError, ValueError):
            point = np.array([np.nan])
        if point.shape not in ((2,), (3,)) or not np.all(np.isfinite(point)):
            raise InvalidParameterError(f"positions[{node!r}]", "a point (x, y) or (x, y, z) of finite numbers (m)",
                                        pos[node])
        pts[i] = point[:2]                       # (drawn in the x-y plane)
    xy = np.stack([pts[result.U], pts[result.V]], axis=1)
    radius = 0.5 * (result.radius_u + result.radius_v)
    widths = max_width * radius / radius.max()
    label, kind, value_of = _NETWORK_COLOURS[color]
    values = np.asarray(value_of(result), dtype=float)
    node_values = result.pressures
    shown = np.concatenate([values, node_values]) if color == "pressure" else values
    low, high = float(shown.min()), float(shown.max())
    norm = Normalize(vmin=low, vmax=high if high > low else low + (abs(low) if low else 1.0))
    ax = _new_axes(ax, (7.0, 5.0))
    lines = LineCollection(xy, linewidths=np.maximum(widths, 0.4), cmap=cmap, norm=norm, capstyle="round", zorder=1)
    lines.set_array(values)
    ax.add_collection(lines)
    if color == "pressure":
        ax.scatter(pts[:, 0], pts[:, 1], c=node_values, cmap=cmap, norm=norm, s=14, edgecolors="k", linewidths=0.4,
                   zorder=2)
    else:
        ax.scatter(pts[:, 0], pts[:, 1], c="0.3", s=4, zorder=2)
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_axis_off()
    if kind is None:
        bar = ax.figure.colorbar(lines, ax=ax, label=label, shrink=0.8)
    else:
        symbol, size = _unit(kind, max(abs(low), abs(high)))
        bar = ax.figure.colorbar(lines, ax=ax, label=f"{label} ({symbol})", shrink=0.8)
        bar.formatter = _scaled_formatter(size)
        bar.update_ticks()
    if not ax.get_title():
        ax.set_title(f"{len(nodes)} nodes, {len(result.tube_names)} tubes; width ~ deformed radius "
                     f"(widest {_fmt_len(float(radius.max()))})", fontsize=10)
    return ax
