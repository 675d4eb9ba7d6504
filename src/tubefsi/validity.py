r"""Where the reduced model holds, checked on the deformed tube (``docs/scope.md``).

:func:`tubefsi.solve` runs :func:`check` on every result (a few vectorized operations on the
inlet state) and issues a :class:`~tubefsi.ModelValidityWarning` per assumption that fails;
:meth:`tubefsi.Solution.diagnostics` reports the same numbers. The assumptions and their
thresholds:

* **slender deformed tube**: lubrication theory drops :math:`O((R/L)^2)` terms and the end
  effects are :math:`O(R/L)`; the largest radius is at the inlet, so
  :math:`R_{in}/L \le` :data:`SLENDERNESS`;
* **the wall law's range**: the inlet hoop strain :math:`\varepsilon_{in} = R_{in}/a - 1` (the
  largest) stays below the wall's ``calibrated_strain`` (0.05 for the small-strain theory of
  linear walls, ``inf`` for the hyperelastic laws unless a subclass narrows it);
* **negligible inertia** (only when the fluid's density :math:`\rho` is given): the reduced
  Metzner–Reed Reynolds number :math:`Re\,R/L = 8\rho V^2/\tau_w \cdot R/L`, with the mean
  velocity :math:`V = q/(\pi R^2)` and the wall shear stress :math:`\tau_w = G R/2`, evaluated
  at both ends of the tube (it is monotone in :math:`R` for a power law), stays below
  :data:`REDUCED_REYNOLDS`.

Silence the warnings the standard way:
``warnings.filterwarnings("ignore", category=tubefsi.ModelValidityWarning)``.
"""

from __future__ import annotations

import math

import attrs
import numpy as np

from .errors import ModelValidityWarning, warn_user
from .walls.linear import ThickLinear, ThinLinear

__all__ = ["SLENDERNESS", "REDUCED_REYNOLDS", "END_LAYER", "Validity", "check", "check_and_warn", "end_effect_error",
           "warn"]

#: Largest deformed slenderness :math:`R/L` for lubrication theory.
SLENDERNESS = 0.1
#: Largest reduced Reynolds number :math:`Re\,R/L` for inertia to be negligible.
REDUCED_REYNOLDS = 0.1
#: Coefficients :math:`(c_a, c_t)` of the clamped inlet's end-layer length
#: :math:`\ell_{end} = c_a a + c_t t`, measured by the validity map (``docs/validity.md``:
#: 0.30, 0.36, 0.50 :math:`a` at :math:`t/a` = 0.05, 0.3, 1 and 5 % strain).
END_LAYER = (0.3, 0.2)


def end_effect_error(flow_index, inlet_strain, radius, thickness, length):
    r"""Expected relative error of the reduced pressure drop from clamped ends, by the validity map.

    :math:`|\delta| \approx (3k+1)\,\varepsilon_{in}\,\ell_{end}/L`, :math:`\ell_{end}` from
    :data:`END_LAYER`, :math:`k` the local flow index (:math:`n` for a power law): the first-order
    term in :math:`a/L` of the fit in ``docs/validity.md``, within 20 % of every map scene at small
    strain (the reduced model *under*-predicts). Not included: the wall theory's own error (thin
    walls, :math:`O(\bar t)`; 0.2 % at 30 % strain) and inertia. Broadcasts; SI units.
    """
    k, eps, a, t, L = (np.asarray(v, dtype=float) for v in (flow_index, inlet_strain, radius, thickness, length))
    return (3.0 * k + 1.0) * np.abs(eps) * (END_LAYER[0] * a + END_LAYER[1] * t) / L


@attrs.frozen
class Validity:
    """The largest value of each checked quantity over a result's points, and the messages."""

    deformed_slenderness: float         # max R_in / L
    max_strain: float                   # max inlet hoop strain
    reduced_reynolds_number: float | None   # max Re R/L over both ends (None: no density)
    reynolds_number: float | None       # the Metzner–Reed Re at the same point
    messages: tuple


def _where(bad, total) -> str:
    return "" if total == 1 else f" at {int(bad)} of {total} points"


def _reynolds(scene, q, radius, density):
    """Metzner–Reed Reynolds number :math:`8\\rho V^2/\\tau_w` per point of a flat scene, at radius
    ``radius`` (both 1-D, aligned with the scene's points; 0 where q = 0)."""
    re = np.zeros(q.shape)
    for index, part in scene.split(np.flatnonzero(q > 0)):
        if index.size == 0:
            continue
        pts = part.at(np.arange(index.size)) if part.size > 1 else part.at(np.zeros(1, dtype=int))
        r = radius[index]
        gradient = np.broadcast_to(pts.rheology._pressure_gradient(q[index], r), index.shape)
        velocity = q[index] / (math.pi * r**2)
        re[index] = 8.0 * np.asarray(density, dtype=float) * velocity**2 / (0.5 * gradient * r)
    return re


def _scalar(value) -> bool:
    return type(value) is float or np.ndim(value) == 0       # (a float: no call into numpy)


def check(scene, flow_rate, inlet_strain, *, density=None) -> Validity:
    """Check a result: ``scene`` a flat scene (:meth:`~tubefsi.scene.Scene.flat`) and the flat
    arrays ``flow_rate``, ``inlet_strain`` of its points (NaN where infeasible)."""
    q = np.ravel(np.asarray(flow_rate, dtype=float))
    strain = np.asarray(inlet_strain, dtype=float)
    if strain.shape != q.shape:
        strain = np.broadcast_to(strain, q.shape)
    a, length = scene.tube.radius, scene.tube.length
    limit = getattr(scene.wall, "calibrated_strain", math.inf)
    if density is None and q.size and _scalar(a) and _scalar(length) and _scalar(limit):
        # one tube (a curve): R_in/L grows with the strain, so the largest strain decides both
        # checks: one reduction, and the per-point pass only when there is something to report
        top = float(np.fmax.reduce(strain, initial=-math.inf))    # NaN (infeasible points) ignored
        worst = float(a) * (1.0 + top) / float(length)
        if not (worst > SLENDERNESS or top > limit):
            return Validity(deformed_slenderness=max(worst, 0.0) if math.isfinite(top) else math.nan,
                            max_strain=top if math.isfinite(top) else math.nan,
                            reduced_reynolds_number=None, reynolds_number=None, messages=())
    ok = np.isfinite(q) & np.isfinite(strain)
    a = np.broadcast_to(np.asarray(scene.tube.radius, dtype=float), q.shape)
    length = np.broadcast_to(np.asarray(scene.tube.length, dtype=float), q.shape)
    r_in = a * (1.0 + strain)
    slender = np.where(ok, r_in / length, -np.inf)
    messages = []
    total = q.size
    worst = float(np.max(slender, initial=-np.inf))
    if worst > SLENDERNESS:
        i = int(np.argmax(slender))
        messages.append(f"the deformed tube is not slender{_where(np.sum(slender > SLENDERNESS), total)}: "
                        f"R_in/L = {worst:.3g} > {SLENDERNESS} (R_in = {r_in[i]:.3g} m, a = {a[i]:.3g} m, "
                        f"L = {length[i]:.3g} m): lubrication theory no longer applies")
    strains = np.where(ok, strain, -np.inf)
    limit = np.broadcast_to(np.asarray(getattr(scene.wall, "calibrated_strain", math.inf), dtype=float), q.shape)
    beyond = strains > limit
    max_strain = float(np.max(strains, initial=-np.inf))
    if np.any(beyond):
        i = int(np.argmax(np.where(beyond, strains, -np.inf)))
        linear = isinstance(scene.wall, (ThinLinear, ThickLinear))
        what = ("with a linear wall (small-strain theory): use a hyperelastic wall" if linear
                else f"the strain range {type(scene.wall).__name__} is calibrated for")
        messages.append(f"inlet hoop strain {strains[i]:.3g} > {limit[i]:.3g}{_where(np.sum(beyond), total)}, "
                        f"{what}")
    rre = re_at = None
    if density is not None and np.any(ok):
        qq = np.where(ok, q, 0.0)
        r_out = a * np.broadcast_to(np.asarray(scene.outlet_stretch, dtype=float), q.shape)
        best = np.full(q.shape, -np.inf)
        re_best = np.zeros(q.shape)
        for radius in (np.where(ok, r_in, a), r_out):
            re = _reynolds(scene, qq, radius, density)
            reduced = re * radius / length
            better = reduced > best
            best = np.where(better, reduced, best)
            re_best = np.where(better, re, re_best)
        i = int(np.argmax(best))
        rre, re_at = float(best[i]), float(re_best[i])
        if rre > REDUCED_REYNOLDS:
            messages.append(f"reduced Reynolds number Re R/L = {rre:.3g} > {REDUCED_REYNOLDS}"
                            f"{_where(np.sum(best > REDUCED_REYNOLDS), total)} (Re = {re_at:.3g}): "
                            "inertia is not negligible")
    return Validity(deformed_slenderness=max(worst, 0.0) if math.isfinite(worst) else math.nan,
                    max_strain=max_strain if math.isfinite(max_strain) else math.nan,
                    reduced_reynolds_number=rre, reynolds_number=re_at, messages=tuple(messages))


def check_and_warn(scene, flow_rate, inlet_strain, *, density=None) -> None:
    """:func:`warn` of :func:`check`, for :func:`tubefsi.solve`: one point of a uniform tube is
    tested in floats first (slender and within the calibrated strain: nothing to say)."""
    if density is None and type(inlet_strain) is float:
        a, length = scene.tube.radius, scene.tube.length
        limit = getattr(scene.wall, "calibrated_strain", math.inf)
        if type(a) is float and type(length) is float and type(limit) is float:
            if not (a * (1.0 + inlet_strain) / length > SLENDERNESS or inlet_strain > limit):
                return
    warn(check(scene, flow_rate, inlet_strain, density=density))


def warn(validity: Validity) -> None:
    """Issue each message of ``validity`` as a :class:`~tubefsi.ModelValidityWarning` at the
    caller's line."""
    for message in validity.messages:
        warn_user(message, ModelValidityWarning)
