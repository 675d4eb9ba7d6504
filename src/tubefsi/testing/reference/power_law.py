r"""Power-law flow in a reference wall, by separation of variables, in ``mpmath``.

Nothing here calls tubefsi. Written from ``docs/theory.md``, sections "The flow law of a
generalized Newtonian fluid" and "Coupling without an ODE", at the caller's ``mp.dps``; the
walls are :class:`~.tube_laws.RefWall` instances.

Power-law fluid: ``G(q, R) = phi(q) R^-k``, ``k = 3n + 1``, ``phi(q) = 2 m [(3n+1) q / (pi n)]^n``
(Newtonian = ``n = 1``, ``m = viscosity``). With the outlet at zero pressure (``lam_out = 1``),
``dp/dz = -G`` separates into ``L phi(q) = a^k Jhat(lam_in)``, ``Jhat(lam) = int_1^lam P'(s) s^k ds``,
evaluated

* without ``P'``, by parts, ``Jhat = P(lam) lam^k - k int_1^lam P(s) s^(k-1) ds`` (``mpmath.quad``,
  tanh–sinh, on geometrically split sub-intervals: :func:`ref_J`; or in ``x = ln s`` on one
  interval: :func:`ref_J_log`), where only the tube law itself enters;
* or directly with ``P'`` (:func:`ref_J_direct`, on the wall's break points, graded toward a
  locking stretch, or split geometrically up to a large stretch: a positive integrand, so no
  cancellation even at ``lam ~ 2000``), and then the inlet stretch of a flow rate by Newton's
  method with ``Jhat' = P' lam^k`` (:func:`inlet_stretch`), or the other way round the double
  flow rate of a given inlet stretch and the exact state for that double
  (:func:`flow_rate_cases`).

Limit walls (thick, thin current thickness; closed forms) and ``k < 4`` (``n < 1``):
``J_inf = int_1^inf P'(s) s^k ds`` is finite (the maximum flow rate, ``docs/theory.md``, section
"Limits"). Thin current: ``J_inf = 4 mu tb / (4 - k)`` and the tail
``int_lam^inf P' s^k ds = 4 mu tb lam^(k-4) / (4 - k)`` exactly. Thick: substituting ``s = 1/t``,
``int_lam^inf P' s^k ds = mu d int_0^(1/lam) ((d+2) + d t^2) t^(3-k) / (1 + d t^2)^2 dt``
(``d = (1+tb)^2 - 1``), and ``t = w^(1/(4-k))`` removes the endpoint singularity ``t^(3-k)``
(without it, tanh–sinh loses ~13 digits at n = 0.9):
``tail(lam) = mu d / (4-k) int_0^(lam^-(4-k)) ((d+2) + d t^2) / (1 + d t^2)^2 dw``
(``J_inf = tail(1)``; cross-checked to ~1e-40 against ``int_1^inf`` of ``P' s^k`` with the
``(d+2) s^(k-5)`` tail subtracted analytically); the maximum flow rate is
``q_max = phi^-1(a^k J_inf / L)`` (:func:`ref_q_max`). Near the maximum flow rate
``Jhat(lam) = J_inf - tail(lam)`` is to be used, since integration by parts at ``lam ~ 1e7``
would cancel ``k log10(lam)`` digits.
"""

from __future__ import annotations

from mpmath import mp, mpf

from .quadrature import geometric_breaks

__all__ = ["ref_phi", "ref_phi_inverse", "ref_J", "ref_J_log", "ref_J_direct", "ref_J_tail", "ref_J_inf",
           "ref_q_max", "inlet_stretch", "flow_rate_cases"]


def ref_phi(q, n, m):
    """phi(q) = 2 m [(3n+1) q / (pi n)]^n, so that G(q, R) = phi(q) R^-(3n+1)."""
    q, n, m = mpf(q), mpf(n), mpf(m)
    return 2 * m * ((3 * n + 1) * q / (mp.pi * n)) ** n


def ref_phi_inverse(phi, n, m):
    """q with ref_phi(q, n, m) = phi."""
    phi, n, m = mpf(phi), mpf(n), mpf(m)
    return mp.pi * n / (3 * n + 1) * (phi / (2 * m)) ** (1 / n)


def ref_J(wall, lam, k):
    """Jhat(lam) = int_1^lam P'(s) s^k ds = P(lam) lam^k - k int_1^lam P(s) s^(k-1) ds."""
    if lam == 1:
        return mpf(0)
    tail = mp.quad(lambda s: wall.P(s) * s ** (k - 1), geometric_breaks(mpf(1), lam))
    return wall.P(lam) * lam**k - k * tail


def ref_J_log(wall, lam, k):
    """Jhat(lam) by parts as :func:`ref_J`, but integrated in x = ln s on one interval:
    ``k int_1^lam P(s) s^(k-1) ds = k int_0^(ln lam) P(e^x) e^(kx) dx`` (3x faster at lam ~ 200)."""
    if lam == 1:
        return mpf(0)
    tail = mp.quad(lambda x: wall.P(mp.exp(x)) * mp.exp(k * x), [0, mp.log(lam)])
    return wall.P(lam) * lam**k - k * tail


def ref_J_direct(wall, lam, k, geometric=False):
    r""":math:`\int_1^\lambda P'(s)s^k ds` directly, on the wall's break points (``P'`` by Leibniz's
    rule for thick walls made of a general material).

    ``geometric=True`` adds the geometric break points of :func:`~.quadrature.geometric_breaks`
    (ratio 2) to them, for a large ``lam`` (a wall without a lock then has exactly those).
    """
    lam, k = mpf(lam), mpf(k)
    if lam == 1:
        return mpf(0)
    pts = wall.breaks(mpf(1), lam)
    if geometric:
        pts = sorted(set(pts) | set(geometric_breaks(mpf(1), lam)))
    return mp.quad(lambda s: wall.dP(s) * s**k, pts)


def ref_J_tail(wall, lam, k):
    """int_lam^inf P'(s) s^k ds, finite for a limit wall (closed forms) and k < 4 (module docstring)."""
    alpha = 4 - k
    if not alpha > 0:
        raise ValueError("the tail is infinite for k >= 4")
    if wall.mu is None or wall.kind not in ("thick", "thin-current"):
        raise ValueError(f"no closed-form tail for {wall!r}")
    if wall.kind == "thin-current":
        return 4 * wall.mu * wall.tb * lam ** (-alpha) / alpha
    d = (1 + wall.tb) ** 2 - 1

    def integrand(w):               # t = w^(1/alpha): t^(3-k) dt = dw / alpha
        t2 = w ** (2 / alpha)
        return ((d + 2) + d * t2) / (1 + d * t2) ** 2

    return wall.mu * d / alpha * mp.quad(integrand, [0, lam ** (-alpha)])


def ref_J_inf(wall, k):
    """J_inf = int_1^inf P'(s) s^k ds (limit walls, k < 4)."""
    if wall.kind == "thin-current" and wall.mu is not None:
        return 4 * wall.mu * wall.tb / (4 - k)
    return ref_J_tail(wall, mpf(1), k)


def ref_q_max(wall, n, m, radius, length):
    """The maximum flow rate ``phi^-1(a^k J_inf / L)`` of a power-law fluid (``m``, ``n < 1``) in a
    limit wall of undeformed inner radius ``radius`` and length ``length`` (:func:`ref_J_inf`)."""
    n, m = mpf(n), mpf(m)
    k = 3 * n + 1
    return ref_phi_inverse(ref_J_inf(wall, k) * mpf(radius) ** k / mpf(length), n, m)


def inlet_stretch(wall, target, k, guess, steps=8):
    """lam with :func:`ref_J_direct` (lam) = target, by Newton's method from ``guess``."""
    lam = mpf(guess)
    for _ in range(steps):
        step = (ref_J_direct(wall, lam, k) - target) / (wall.dP(lam) * lam ** mpf(k))
        lam -= step
        if abs(step) < mpf(10) ** (-mp.dps + 4) * lam:
            break
    return lam


def flow_rate_cases(wall, n, m, radius, length, stretches):
    """Flow-controlled reference cases of a power-law fluid (``m``, ``n``) in ``wall`` (undeformed
    inner radius ``radius``, length ``length``, outlet at zero pressure), one near each inlet
    stretch of ``stretches``.

    For each stretch ``lam``: the flow rate ``q`` with ``L phi(q) = a^k Jhat(lam)``
    (:func:`ref_J_direct` split geometrically), rounded to the double ``float(q)`` a library
    receives; then one Newton step in ``lam`` (``Jhat' = P' lam^k``) moves the state to the exact
    one of that double (the rounding moves ``lam`` by ~1e-16 relative, times the condition
    number, so the neglected second-order term is far below the working precision; without the
    step the rounding would show near a limit).

    Returns three lists: the doubles ``q``, and the exact pressure drops ``P(lam)`` and inlet
    displacements ``a (lam - 1)`` (mpf) for them.
    """
    n, m, a, length = mpf(n), mpf(m), mpf(radius), mpf(length)
    k = 3 * n + 1
    qs, dps, us = [], [], []
    for lam in stretches:
        lam = mpf(lam)
        J = ref_J_direct(wall, lam, k, geometric=True)
        q = float(ref_phi_inverse(J * a**k / length, n, m))
        target = length * ref_phi(mpf(q), n, m) / a**k
        lam = lam + (target - J) / (wall.dP(lam) * lam**k)
        qs.append(q)
        dps.append(wall.P(lam))
        us.append(a * (lam - 1))
    return qs, dps, us
