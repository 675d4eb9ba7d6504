r"""Generalized Newtonian flow in a reference wall, in ``mpmath``.

Nothing here calls tubefsi. Everything is written from ``docs/theory.md`` (sections "The flow law
of a generalized Newtonian fluid" and "Coupling without an ODE") at the caller's ``mp.dps``, with
fixed Gauss–Legendre rules (24 nodes, :mod:`.quadrature`) on geometrically graded
sub-intervals, so that a whole solve costs well under a second. The wall is a
:class:`~.tube_laws.RefWall` (only its ``P`` and ``dP`` enter).

Fluid (Carreau–Yasuda): :math:`\tau(x) = x[\eta_\infty + (\eta_0-\eta_\infty)(1 + (\lambda x)^a)^{(n-1)/a}]`,
:math:`\tau'(x) = \eta_\infty + (\eta_0-\eta_\infty)(1+(\lambda x)^a)^{(n-1)/a - 1}(1 + n(\lambda x)^a)`;
or any law given by its shear rate :math:`\dot\gamma(\tau)`, zero below a yield stress
(:class:`RateLawRef`).

The tube flow is parametrized by the wall *shear rate* :math:`g` (by the wall stress for a rate
law), which avoids inverting the constitutive law: with :math:`\tau = \tau(x)` substituted in the
Rabinowitsch–Mooney integral,

.. math::

    \Gamma(g) = \frac{4q}{\pi R^3} = \frac{4}{\tau(g)^3}\int_0^g \tau(x)^2\tau'(x)\,x\,dx,
    \qquad \frac{d\Gamma}{dg} = \frac{\tau'(g)}{\tau(g)}(4g - 3\Gamma),

and at fixed flow rate :math:`q` a section of wall shear rate :math:`g` has radius
:math:`R = (4q/\pi\Gamma)^{1/3}` and pressure gradient :math:`G = 2\tau(g)/R`. Separating
:math:`dp/dz = -G`, :math:`p = P(\lambda)` (outlet at zero pressure, :math:`\lambda = 1`):

.. math::

    L = \int_1^{\lambda_{in}} \frac{P'(\lambda)}{G}\,d\lambda
      = \int_{g_{in}}^{g_{out}} \frac{P'(\lambda(g))\,\lambda(g)}{3\,G(g)}\frac{\Gamma'(g)}{\Gamma(g)}\,dg .

:math:`g_{in}` is found by Newton's method on this identity (its derivative is minus the
integrand at :math:`g_{in}`), the cumulative integral :math:`\int_0^g` along the sorted
outer nodes, and :math:`\Delta p = P(\lambda_{in})`.

The tests use a thick neo-Hookean wall derived from its strain energy,
``RefWall("thick", NeoHookean(mu), tb, closed_form=False)``: the Lamé integral
:math:`P(\lambda) = \int_{\lambda_o}^{\lambda}\mu(s^2+1)/s^3\,ds` by ``mpmath.quad`` and, by
Leibniz, :math:`P'(\lambda) = h(\lambda) - h(\lambda_o)\lambda/(b\lambda_o)`, :math:`b = (1+\bar t)^2`,
:math:`\lambda_o^2 = 1 + (\lambda^2-1)/b` (``docs/theory.md``, section "Tube laws", subsection
"Thick walls").
"""

from __future__ import annotations

from mpmath import mp, mpf

from .quadrature import gauss_legendre, gauss_legendre_rule, geometric_breaks

__all__ = ["CarreauYasudaRef", "RateLawRef", "section", "solve_flow_controlled", "solve_pressure_controlled",
           "yield_pressure_drop", "velocity"]


class CarreauYasudaRef:
    """Parametrized by the wall shear rate ``x``: wall stress ``tau(x)``, I = int_0^x tau^2 tau' x."""

    lower = mpf(0)

    def __init__(self, eta0, eta_inf, relaxation_time, index, transition, m=24):
        self.e0, self.einf = mpf(eta0), mpf(eta_inf)
        self.lam, self.n, self.a = mpf(relaxation_time), mpf(index), mpf(transition)
        self.m = m

    def tau(self, x):
        y = (self.lam * x) ** self.a
        return x * (self.einf + (self.e0 - self.einf) * (1 + y) ** ((self.n - 1) / self.a))

    def dtau(self, x):
        y = (self.lam * x) ** self.a
        return self.einf + (self.e0 - self.einf) * (1 + y) ** ((self.n - 1) / self.a - 1) * (1 + self.n * y)

    def _w(self, x):
        t = self.tau(x)
        return t * t * self.dtau(x) * x

    def stress(self, x):
        return self.tau(x)

    def dlog_apparent(self, x, gam):
        """d ln(Gamma) / dx."""
        return self.dtau(x) / self.tau(x) * (4 * x - 3 * gam) / gam

    def integral(self, g):
        r""":math:`I(g) = \int_{lower}^g w` on panels halving toward the lower end until negligible."""
        total, hi = mpf(0), g
        eps = mpf(10) ** (-mp.dps - 5)
        while True:
            lo = self.lower + (hi - self.lower) / 2
            part = gauss_legendre(self._w, lo, hi, self.m)
            total += part
            hi = lo
            if abs(part) < eps * abs(total):
                return total

    def cumulative(self, g0, I0, points):
        """I at each of the increasing ``points`` (> g0), from I(g0) = I0, piece by piece."""
        out, prev, acc = [], g0, I0
        for g in points:
            br = geometric_breaks(prev - self.lower, g - self.lower)
            for lo, hi in zip(br[:-1], br[1:]):
                acc += gauss_legendre(self._w, self.lower + lo, self.lower + hi, self.m)
            out.append(acc)
            prev = g
        return out

    def apparent_rate(self, g, I=None):
        I = self.integral(g) if I is None else I
        return 4 * I / self.stress(g) ** 3

    def at_apparent(self, target, guess):
        """The parameter x with Gamma(x) = target (Newton on ln Gamma, exact derivative)."""
        g = mpf(guess)
        for _ in range(200):
            gam = self.apparent_rate(g)
            step = mp.log(gam / target) / self.dlog_apparent(g, gam)
            g_new = g - step
            if g_new <= self.lower:        # stay in the yielded range
                g_new = self.lower + (g - self.lower) / 4
            if abs(g_new - g) < abs(g) * mpf(10) ** (-mp.dps + 3):
                return g_new
            g = g_new
        raise ArithmeticError("no convergence")

    rate_at_apparent = at_apparent


class RateLawRef(CarreauYasudaRef):
    r"""A law given by its shear rate :math:`\dot\gamma(\tau)` (zero below ``yield_stress``),
    parametrized by the wall stress ``x``: :math:`I(x) = \int_{\tau_y}^x \tau^2\dot\gamma\,d\tau`,
    :math:`d\ln\Gamma/dx = (4\dot\gamma(x) - 3\Gamma)/(x\Gamma)`."""

    def __init__(self, shear_rate, yield_stress=0, m=24):
        self.rate, self.lower, self.m = shear_rate, mpf(yield_stress), m

    def _w(self, t):
        return t * t * self.rate(t)

    def stress(self, x):
        return x

    def dlog_apparent(self, x, gam):
        return (4 * self.rate(x) - 3 * gam) / (x * gam)


def _state(fluid, wall, a, q, x, I):
    """(stretch, integrand of the length) at the wall parameter ``x`` (``I`` its integral)."""
    gam = 4 * I / fluid.stress(x) ** 3
    R = (4 * q / (mp.pi * gam)) ** (mpf(1) / 3)
    lam = R / a
    G = 2 * fluid.stress(x) / R
    return lam, wall.dP(lam) * lam / 3 * fluid.dlog_apparent(x, gam) / G


def _length(fluid, wall, a, q, x_in, I_in, x_out, m):
    r""":math:`H = \int_{x_{in}}^{x_{out}} P'(\lambda)\lambda\,(d\ln\Gamma/dx)/(3G)\,dx` (the tube length
    that carries ``q`` between those wall parameters) and the integrand at ``x_in``."""

    def state(x, I):
        return _state(fluid, wall, a, q, x, I)

    nodes, weights = gauss_legendre_rule(m)
    pieces = [fluid.lower + d for d in geometric_breaks(x_in - fluid.lower, x_out - fluid.lower)]
    H = mpf(0)
    for lo, hi in zip(pieces[:-1], pieces[1:]):
        c, w = (lo + hi) / 2, (hi - lo) / 2
        xs = [c + w * x for x in nodes]
        order = sorted(range(m), key=lambda i: xs[i])
        Is = fluid.cumulative(x_in, I_in, [xs[i] for i in order])
        vals = {i: state(xs[i], I)[1] for i, I in zip(order, Is)}
        H += w * mp.fsum(weights[i] * vals[i] for i in range(m))
    lam_in, phi_in = state(x_in, I_in)
    return H, phi_in, lam_in


def section(fluid, wall, radius, to_outlet, q, stretch_guess, m=24, newton=8, outlet_stretch=1):
    r"""``(x, lam)``: the wall parameter and the stretch of the section a length ``to_outlet``
    upstream of the outlet (:math:`L - z`) at the flow rate ``q``: Newton's method on
    :math:`\int_{x}^{x_{out}} P'(\lambda)\,\lambda\,(d\ln\Gamma/dx)/(3G)\,dx = L - z` (its
    derivative is minus the integrand at :math:`x`), the outlet at the stretch ``outlet_stretch``."""
    a, q = mpf(radius), mpf(q)
    target = mpf(to_outlet)
    lam_out = mpf(outlet_stretch)
    gam_out = 4 * q / (mp.pi * (a * lam_out) ** 3)
    x_out = fluid.at_apparent(gam_out, _guess(fluid, gam_out))
    lam0 = mpf(stretch_guess)
    x = fluid.at_apparent(4 * q / (mp.pi * (a * lam0) ** 3), _guess(fluid, gam_out / (lam0 / lam_out) ** 3))
    for _ in range(newton):
        H, phi, _ = _length(fluid, wall, a, q, x, fluid.integral(x), x_out, m)
        x += (H - target) / phi
        if abs(H / target - 1) < mpf(10) ** (-mp.dps + 5):
            break
    lam, _ = _state(fluid, wall, a, q, x, fluid.integral(x))
    return x, lam


def solve_flow_controlled(fluid, wall, radius, length, q, stretch_guess, m=24, newton=8, outlet_stretch=1):
    r"""(pressure drop, inlet stretch) of the flow-controlled problem; the outlet at the stretch
    ``outlet_stretch`` (1: unloaded; else where the wall's transmural pressure is the outlet's).

    ``fluid`` is a :class:`CarreauYasudaRef` (parameter: wall shear rate) or a :class:`RateLawRef`
    (parameter: wall stress); the separated identity is integrated over that parameter ``x``
    (:func:`section` at ``to_outlet = L``):
    :math:`L = \int_{x_{in}}^{x_{out}} P'(\lambda)\,\lambda\,(d\ln\Gamma/dx)/(3G)\,dx`, and
    :math:`\Delta p = P(\lambda_{in}) - P(\lambda_{out})`.
    """
    lam_out = mpf(outlet_stretch)
    _, lam_in = section(fluid, wall, radius, length, q, stretch_guess, m, newton, outlet_stretch)
    return wall.P(lam_in) - (wall.P(lam_out) if lam_out != 1 else 0), lam_in


def solve_pressure_controlled(fluid, wall, radius, length, inlet_stretch, outlet_stretch, q_guess, m=24):
    r"""The flow rate between the inlet and outlet stretches (the wall's stretches at the inlet's and
    the outlet's transmural pressures): the root of :math:`\ln H(q) = \ln L` in :math:`\ln q`
    (secant steps from ``q_guess`` and :math:`e^{10^{-3}}` times it, to the working precision), :math:`H` the
    length of :func:`solve_flow_controlled`'s identity between the wall parameters of the two
    stretches at that flow rate."""
    a, L = mpf(radius), mpf(length)
    lam_in, lam_out = mpf(inlet_stretch), mpf(outlet_stretch)
    last = {}

    def log_excess(log_q):
        q = mp.exp(log_q)
        gam_out = 4 * q / (mp.pi * (a * lam_out) ** 3)
        gam_in = 4 * q / (mp.pi * (a * lam_in) ** 3)
        # each wall parameter from the last one found (a start only: Newton to the working precision)
        x_out = fluid.at_apparent(gam_out, last.get("out", _guess(fluid, gam_out)))
        x_in = fluid.at_apparent(gam_in, last.get("in", _guess(fluid, gam_in)))
        last["out"], last["in"] = x_out, x_in
        return mp.log(_length(fluid, wall, a, q, x_in, fluid.integral(x_in), x_out, m)[0]) - mp.log(L)

    s0, s1 = mp.log(mpf(q_guess)), mp.log(mpf(q_guess)) + mpf("1e-3")
    f0, f1 = log_excess(s0), log_excess(s1)
    for _ in range(30):
        s0, s1, f0 = s1, s1 - f1 * (s1 - s0) / (f1 - f0), f1
        if abs(s1 - s0) < mpf(10) ** (-mp.dps + 6):
            return mp.exp(s1)
        f1 = log_excess(s1)
    raise ArithmeticError("no convergence")


def _guess(fluid, gam):
    """A starting value for ``at_apparent``: Newtonian-like with the zero-rate viscosity, or above yield."""
    if isinstance(fluid, RateLawRef):
        x = fluid.lower * 2 + 1
        return x
    return gam


def yield_pressure_drop(yield_stress, wall, radius, length):
    r"""The pressure drop as :math:`q \to 0^+`: :math:`G = 2\tau_y/R`, so
    :math:`L = \int_1^{\lambda_{in}} P'(\lambda)\,a\lambda/(2\tau_y)\,d\lambda`; returns :math:`P(\lambda_{in})`."""
    a, L, ty = mpf(radius), mpf(length), mpf(yield_stress)
    H = lambda lam: mp.quad(lambda s: wall.dP(s) * a * s / (2 * ty), [1, lam])
    lam = mp.findroot(lambda lam: H(lam) - L, mpf(1) + mpf("1e-3"))
    return wall.P(lam)


def velocity(rate, radius, gradient, r, yield_stress=0):
    r""":math:`v(r) = \int_{\max(r, r_p)}^R \dot\gamma(G\rho/2)\,d\rho` (``mpmath.quad``)."""
    R, G, r = mpf(radius), mpf(gradient), mpf(r)
    start = max(r, min(R, 2 * mpf(yield_stress) / G))
    if start >= R:
        return mpf(0)
    return mp.quad(lambda rho: rate(G * rho / 2), [start, R])
