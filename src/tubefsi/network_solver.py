r"""Newton's method for the steady flow through a :class:`~tubefsi.Network` (``docs/network.md``).

Nodes carry pressures :math:`p_i` (transmural, gauge); a tube :math:`e = (u, v)` carries the
flow :math:`q_e = Q_e(p_u, p_v)` of the pressure-controlled single-tube problem, solved from the
higher-pressure end, so that the edge law is odd in :math:`p_u - p_v`:
:math:`Q_e = \operatorname{sign}(p_u - p_v)\,Q(|p_u - p_v|;\ \min(p_u, p_v))` (a graded tube's
:math:`Q` is that of the tube read from the end its flow enters, so its law is not odd:
:mod:`tubefsi.network_groups`). At every node
without a fixed pressure Kirchhoff's law holds,

.. math::  F_i(p) = \sum_{e:\,v_e = i} q_e - \sum_{e:\,u_e = i} q_e + s_i + (p_{d,i} - p_i)/R_i = 0,

with :math:`s_i` the injected flow rate and, at a resistance outlet, :math:`R_i` its terminal
resistance to the distal pressure :math:`p_{d,i}` (the term is absent elsewhere). The free pressures solve :math:`F = 0` by Newton's
method: the Jacobian is assembled from the analytic derivatives :math:`\partial q/\partial p_{in}`
and :math:`\partial q/\partial p_{out}` of each tube (``docs/theory.md``, section
"Sensitivities") and factorized by :func:`scipy.sparse.linalg.splu`. Every tube of a network is
evaluated in one broadcast :func:`tubefsi.solve` per iteration and per group of tubes that
share their wall and fluid classes (their parameters stacked into arrays).

Globalization: the start is a Newtonian network (each tube a Hagen–Poiseuille conductance
:math:`\pi R^4/(8\mu L)`, rigid at the viscosity at 1/s, then refined by three Picard sweeps,
each with the tube inflated to :math:`R = a(1+\varepsilon)` by its wall's hoop strain at the mean
of its end pressures and the fluid's apparent viscosity in it: the secant :math:`|q|/(L\,G(|q|, R))`);
every Newton step is cut to stay inside
:math:`0 \le p_i < p_{lim}` (a step goes at most 90 % of the way to a tube's limit pressure at
that node, or to zero; a graded tube's interior is checked by its own solve) and then halved until the residual norm :math:`\|F\|_2` decreases (Armijo). The derivative of a tube without flow is
degenerate — :math:`\partial q/\partial p \to 0` for a shear-thinning fluid, :math:`\infty` for a
shear-thickening one, as :math:`\Delta p \to 0` — so a tube whose pressure drop is below
:math:`10^{-8}` of the largest pressure enters the Jacobian with its secant conductance
:math:`q/\Delta p` (which zeroes the flow into a dead end in one step; the rigid start
conductance at :math:`\Delta p = 0`), and no conductance goes below :math:`10^{-8}` of the rigid
start one. That changes the step only, never the residual, so the converged pressures are those
of the exact edge laws. (A drop below :math:`10^{-30}` of the largest pressure is taken as
zero; the flow it would carry is below :math:`10^{-30/n}` of the network's.)

A trial pressure beyond what a wall's tube law reaches halves the step; a flow rate the
single-tube solve cannot give at a drop far below the pressures (NaN, the generic rheology path)
is the secant of a probe drop (``docs/network.md``). A node with an inflow and a single
tube is no unknown: that tube is solved flow-controlled at the end.

Inflows beyond the network's capacity: a node pushed into its limit pressure is held there (an
active set, ``_Solver._pinned_done``); an excess left there raises ``NoSteadyStateError`` whose
``limit`` is the flow the network carries so (``_Solver._capacity_error``).

Converged means that the mass balance of every free node is below ``rtol`` times the
throughput (the total flow that enters the network); otherwise :class:`ConvergenceError`.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph
from scipy.sparse import linalg as spla

from .errors import (AccuracyWarning, ConvergenceError, InvalidParameterError, NoSteadyStateError, warn_user)
from .network_groups import _Groups
from .network_solution import NetworkSolution, _hashable


#: Jacobian conductances are clipped to [_CLIP, 1/_CLIP] times the rigid start conductance
_CLIP = 1e-8
#: linear solves of the start: the rigid tubes at the viscosity at 1/s, then Picard sweeps, each with
#: the tubes inflated at their mean pressures and the apparent viscosity there (``_Solver._rigid_start``)
_SWEEPS = 4
#: fraction of the way to a bound (a limit pressure, zero) that one Newton step may go
_TO_BOUND = 0.9
#: a tube whose pressure drop is below this times the largest pressure counts as without flow
#: (its Jacobian entry is the secant); below _TINY times it the drop is zero
_STILL = 1e-8
_TINY = 1e-30
#: a node this close (relative) to its bound with the step still pushing outward is at the bound
_AT_BOUND = 1e-12
#: a node within this (relative) of its bound whose step into it the line search must cut is held
#: at the bound (an active set: ``_Solver._pinned_done``); farther away such a cut is a one-off
_NEAR_BOUND = 1e-2


class _Solver:
    """Newton's method on the Kirchhoff system of a snapshot of a :class:`~tubefsi.Network`."""

    def __init__(self, net):
        if not net._tubes:
            raise InvalidParameterError("network", "at least one tube", 0)
        for node in list(net._pressure) + list(net._inflow) + list(net._resistance):
            if node not in net._nodes:
                raise InvalidParameterError("node", "a node of some tube", node, "it has a boundary condition "
                                            "but no tube")
        self.net = net
        self.nodes = list(net._nodes)
        index = net._nodes
        self.tubes = net._tubes.columns(index)          # (columns: no Python object per tube)
        n_nodes, n_tubes = len(self.nodes), len(self.tubes)
        self.U, self.V = self.tubes.U, self.tubes.V
        # the boundary conditions, node by node (one indexing per kind)
        self.fixed = np.zeros(n_nodes, dtype=bool)
        self.p_fixed = np.zeros(n_nodes)
        at, values = _at(index, net._pressure)
        self.fixed[at], self.p_fixed[at] = True, values
        self.source = np.zeros(n_nodes)
        at, values = _at(index, net._inflow)
        self.source[at] = values
        # resistance outlets: q = g (p - p_d) leaves node i, g = 1/R (0 elsewhere)
        self.g_out = np.zeros(n_nodes)
        self.p_distal = np.zeros(n_nodes)
        at, values = _at(index, net._resistance)
        self.g_out[at], self.p_distal[at] = (1.0 / values[:, 0], values[:, 1]) if at.size else (0.0, 0.0)
        self._check_connected(n_nodes)
        # a feeder: a node with an inflow and one tube; that tube's flow is known, so it is solved
        # flow-controlled after the rest (no pressure unknown near a limit pressure at the inlet)
        degree = np.bincount(self.U, minlength=n_nodes) + np.bincount(self.V, minlength=n_nodes)
        feeds = ~self.fixed & (self.source > 0) & (degree == 1)
        self.feeder = feeds[self.U] | feeds[self.V]
        self.feed_node = np.where(feeds[self.U], self.U, self.V)
        self.feeds = feeds
        self.groups = _Groups(self.tubes, ~self.feeder)
        self.feed_groups = _Groups(self.tubes, self.feeder)
        # per tube, the limit pressures at its ends u and v (a graded tube's differ: ``_Groups``)
        self.limit_u = np.where(self.feeder, self.feed_groups.limit_u, self.groups.limit_u)
        self.limit_v = np.where(self.feeder, self.feed_groups.limit_v, self.groups.limit_v)
        self.radius = np.where(self.feeder, self.feed_groups.radius, self.groups.radius)
        self.radius0_u = np.where(self.feeder, self.feed_groups.radius_u, self.groups.radius_u)
        self.radius0_v = np.where(self.feeder, self.feed_groups.radius_v, self.groups.radius_v)
        self.length = np.where(self.feeder, self.feed_groups.length, self.groups.length)
        # a node's bound: the smallest limit pressure of its tubes at their ends there (an inlet
        # must stay below it; a graded tube's interior is checked by its own solve)
        self.p_limit = np.full(n_nodes, np.inf)
        np.minimum.at(self.p_limit, self.U, self.limit_u)
        np.minimum.at(self.p_limit, self.V, self.limit_v)
        over = self.fixed & (self.p_fixed >= self.p_limit)
        if np.any(over):
            i = int(np.flatnonzero(over)[0])
            raise NoSteadyStateError("pressure", self.p_limit[i], self.p_fixed[i],
                                     f"node {self.nodes[i]!r} is fixed at or beyond the limit pressure of tube "
                                     f"{self._limiting_tube(i)!r}")
        self._check_outlet_capacity()
        self.n_tubes = n_tubes
        self.unknown = None
        self._unknowns(~self.fixed)

    def _check_outlet_capacity(self):
        """Without a fixed pressure, all that enters leaves by the resistance outlets, each taking
        at most :math:`(p_{lim} - p_d)/R` below its node's limit pressure: net inflows beyond that
        sum have no steady state (``NoSteadyStateError`` at once, naming it)."""
        if np.any(self.fixed):
            return
        outlets = np.flatnonzero(self.g_out)
        capacity = float(np.sum(self.g_out[outlets] * (self.p_limit[outlets] - self.p_distal[outlets])))
        inflow = float(np.sum(self.source))
        if inflow > capacity:
            i = int(outlets[np.argmin(self.p_limit[outlets])])
            raise NoSteadyStateError("flow_rate", capacity, inflow,
                                     f"the network's capacity is at most this, what the resistance outlets take "
                                     f"with every outlet node at its limit pressure, sum (p_lim - p_d)/R (e.g. node "
                                     f"{self.nodes[i]!r} at the limit pressure {self.p_limit[i]:.6g} Pa of tube "
                                     f"{self._limiting_tube(i)!r}); the tubes upstream may carry less",
                                     name="the net inflow")

    def _check_connected(self, n):
        graph = sp.coo_matrix((np.ones(self.U.size), (self.U, self.V)), shape=(n, n))
        count, labels = csgraph.connected_components(graph, directed=False)
        anchor = self.fixed | (self.g_out > 0)
        if not np.any(anchor):
            raise InvalidParameterError("network", "at least one node with a fixed pressure or a resistance outlet",
                                        None, "set_pressure(node, p) or set_resistance(node, R) on an outlet")
        anchored = np.zeros(count, dtype=bool)
        anchored[labels[anchor]] = True
        if not np.all(anchored):
            c = int(np.flatnonzero(~anchored)[0])
            members = [self.nodes[i] for i in np.flatnonzero(labels == c)]
            raise InvalidParameterError("network", "every node connected to a fixed pressure or a resistance "
                                        "outlet",
                                        members[0], f"a component of {len(members)} node(s), disconnected "
                                        f"from every fixed pressure: {members[:5]!r}")

    def _unknowns(self, mask):
        """Make the nodes of ``mask`` the unknowns (the rigid start: every free node; Newton: the
        free nodes but the feeders)."""
        if self.unknown is not None and np.array_equal(mask, self.unknown):
            return                           # the same unknowns: the Jacobian's pattern is kept
        self.unknown = mask
        self.free = np.flatnonzero(mask)
        self.where = np.full(mask.size, -1)
        self.where[self.free] = np.arange(self.free.size)
        self._pattern = None                 # built by the next _jacobian

    def _limiting_tube(self, i):
        """The name of the tube whose limit pressure at node ``i`` is the node's bound."""
        at = np.flatnonzero((self.U == i) | (self.V == i))
        limit = np.where(self.U[at] == i, self.limit_u[at], self.limit_v[at])
        return self.tubes[int(at[np.argmin(limit)])].name

    # ------------------------------------------------------------------ linear algebra
    def _jacobian(self, gu, gv):
        """dF/dp over the free nodes from dq_e/dp_u = gu, dq_e/dp_v = gv, and the exact -1/R of
        each resistance outlet on the diagonal; in the order of :class:`_Pattern` (the unknowns'
        fill-reducing order once a first factorization has found it)."""
        if self._pattern is None:
            self._pattern = _Pattern(self, None)
        outlets = np.flatnonzero(self.g_out)
        vals = np.concatenate([-gu, -gv, gu, gv, -self.g_out[outlets]])
        return self._pattern.matrix(vals)

    def _balance(self, q, p):
        """Net inflow at every node: sum of q into it - sum out of it + injection + what a
        resistance outlet supplies, (p_d - p)/R."""
        n = len(self.nodes)
        return (np.bincount(self.V, q, n) - np.bincount(self.U, q, n)) + self._supplied(p)

    def _supplied(self, p):
        """What the boundary supplies at the nodes without a fixed pressure: the injections and the
        resistance outlets' flows (negative where they take flow out)."""
        return self.source + self.g_out * (self.p_distal - p)

    def _rigid_start(self):
        """Pressures of the start (Picard sweeps on the Newtonian network of each tube's apparent
        conductance: the rigid tube at the viscosity at 1/s, then each tube inflated by its wall's
        strain at the mean of its end pressures of the sweep before, at the fluid's apparent
        viscosity in that inflated tube at the flow of the sweep before), and the last sweep's
        conductances (the Jacobian's reference scale)."""
        a, length = self.radius, self.length
        mu = np.where(self.feeder, self.feed_groups.nominal_viscosity(self.n_tubes),
                      self.groups.nominal_viscosity(self.n_tubes))
        good = np.isfinite(mu) & (mu > 0)
        mu = np.where(good, mu, np.median(mu[good]) if np.any(good) else 1e-3)
        stretch = np.ones(self.n_tubes)
        p = self.p_fixed.copy()
        for sweep in range(_SWEEPS):
            radius = a * stretch
            c = math.pi * radius**4 / (8 * mu * length)
            rhs = self._supplied(np.zeros_like(p))
            # K p = s with K the weighted Laplacian; move the fixed columns to the right
            known = np.where(self.fixed, self.p_fixed, 0.0)
            flow = c * (known[self.U] - known[self.V])
            rhs += np.bincount(self.V, flow, len(self.nodes)) - np.bincount(self.U, flow, len(self.nodes))
            jac = self._jacobian(c, -c)
            p[self.free] = self._linear_solve(jac, -rhs[self.free]) if self.free.size else p[self.free]
            if sweep < _SWEEPS - 1:
                q = c * (p[self.U] - p[self.V])
                stretch = self._stretch(p)
                mu = self.feed_groups.apparent_viscosity(q, self.groups.apparent_viscosity(q, mu, stretch), stretch)
        self._unknowns(~self.fixed & ~self.feeds)
        return p, c

    def _stretch(self, p):
        """Per tube, its wall's hoop stretch at the mean of its end pressures ``p`` (the start only;
        1 where ``p`` is not below every node's bound, or beyond what a wall's tube law reaches: no
        steady state may exist there, and the tubes stay rigid)."""
        if not np.all(p < self.p_limit):
            return np.ones(self.n_tubes)
        mid = 0.5 * (p[self.U] + p[self.V])
        try:
            return 1.0 + self.feed_groups.strain(mid) + self.groups.strain(mid)
        except NoSteadyStateError:          # (a tube law that peaks below its limit pressure)
            return np.ones(self.n_tubes)

    # ------------------------------------------------------------------ Newton
    def _edges(self, p, named=False):
        """Per tube at the node pressures ``p``: its flow (u to v), its derivatives by p_u and p_v
        (the Jacobian's, see the module's docstring) and its deformed radii at u and v. A tube
        without a steady state raises NoSteadyStateError (naming it where ``named``)."""
        du = p[self.U] - p[self.V]
        forward = du >= 0
        drop = np.abs(du)
        drop[drop <= _TINY * float(np.max(p))] = 0.0      # flow ~ (1e-30)^(1/n) of the network's
        outlet = np.where(forward, p[self.V], p[self.U])
        q, d_in, d_out, r_in, r_out = self.groups.evaluate(drop, outlet, forward, named)
        bad = ~np.isfinite(q)
        if np.any(bad):
            q, d_in, d_out = self._tiny_drops(bad, drop, outlet, forward, q, d_in, d_out, float(np.max(p)))
        if self.feed_groups.parts:         # the feeders' known flows (their nodes are no unknowns)
            forward = np.where(self.feeder, self.feed_node == self.U, forward)
            q = np.where(self.feeder, self.source[self.feed_node], q)
            d_in, d_out, drop = (np.where(self.feeder, 0.0, x) for x in (d_in, d_out, drop))
        sign = np.where(forward, 1.0, -1.0)
        gu = np.where(forward, d_in, -d_out)
        gv = np.where(forward, d_out, -d_in)
        # a tube (almost) without flow: dq/dp -> 0 (shear-thinning) or inf (shear-thickening); the
        # secant q/dp instead (it zeroes a dead end in one step), the rigid start conductance at dp = 0
        still = (drop <= _STILL * float(np.max(p))) & ~self.feeder
        if np.any(still):
            with np.errstate(divide="ignore", invalid="ignore"):
                secant = np.where(drop[still] > 0, q[still] / drop[still], self.c[still])
            secant = np.where(np.isfinite(secant) & (secant > 0), secant, self.c[still])
            gu[still], gv[still] = secant, -secant
        r_u, r_v = np.where(forward, r_in, r_out), np.where(forward, r_out, r_in)
        return sign * q, gu, gv, r_u, r_v

    def _linear_solve(self, jac, rhs):
        """Solve ``jac x = rhs`` (``jac`` from :meth:`_jacobian`, ``rhs`` and ``x`` over the free
        nodes in their own order). The first factorization of a pattern orders its columns by
        minimum degree on A^T + A (the pattern is symmetric, a graph's: less fill than the default
        COLAMD); the Jacobian is then assembled in that order, so that every later factorization
        keeps it (``permc_spec="NATURAL"``) instead of computing it again. No relaxed supernodes and
        panels of one column: a network's Jacobian is so sparse (a graph's pattern) that SuperLU's
        supernode machinery costs more than it saves (per factorization, the 10^5-tube tree of
        ``benchmarks/network_scale.py``: 10 ms against 25 ms; its lattice: 88 ms against 128 ms)."""
        pattern = self._pattern
        try:
            if pattern.order is None:
                lu = spla.splu(jac, permc_spec="MMD_AT_PLUS_A", relax=1, panel_size=1)
                self._pattern = _Pattern(self, lu.perm_c)
                return lu.solve(rhs)
            # position order[i] holds free node i: solve for the positions, read them back per node
            lu = spla.splu(jac, permc_spec="NATURAL", relax=1, panel_size=1)
            return lu.solve(rhs[pattern.inverse])[pattern.order]
        except RuntimeError as exc:          # an exactly singular Jacobian
            raise ConvergenceError(f"network: singular Jacobian ({exc})") from None

    def _tiny_drops(self, bad, drop, outlet, forward, q, d_in, d_out, scale):
        """Flows the single-tube solve could not give (NaN): at a pressure drop far below the
        network's pressures the generic rheology path may not resolve the flow. Such a tube is in
        its linear (zero-shear) regime, so its flow is the secant of a probe drop of 1e-8 of the
        largest pressure (1e-6 if that fails too), scaled to its drop; anything else raises."""
        q, d_in, d_out = q.copy(), d_in.copy(), d_out.copy()
        todo = bad & (drop > 0) & (drop < 1e-6 * scale)
        for probe_ratio in (1e-8, 1e-6):
            if not np.any(todo):
                break
            probe = np.where(todo, np.maximum(drop, probe_ratio * scale), drop)
            mask = np.zeros_like(todo)
            for part in self.groups.parts:
                mask[part.index] = todo[part.index]
            sub = _Groups(self.tubes, mask)
            qp, _, _, _, _ = sub.evaluate(probe, outlet, forward)
            ok = todo & np.isfinite(qp)
            secant = np.where(ok, qp / np.where(ok, probe, 1.0), 0.0)
            q[ok], d_in[ok], d_out[ok] = secant[ok] * drop[ok], secant[ok], -secant[ok]
            todo &= ~ok
        left = ~np.isfinite(q)
        if np.any(left):
            i = int(np.flatnonzero(left)[0])
            raise ConvergenceError(f"network: the single-tube solve of tube {self.tubes[i].name!r} gave no flow "
                                   f"rate at pressure drop {drop[i]:.6g} Pa, outlet pressure {outlet[i]:.6g} Pa")
        return q, d_in, d_out

    def run(self, rtol, max_iterations, shown=None, start=None):
        p, c = self._rigid_start()
        self.c = c
        free = self.free
        if start:                      # a warm start: the given pressures at the free nodes they name
            index = self.net._nodes
            for node, value in start.items():
                i = index.get(node) if _hashable(node) else None
                if i is not None and not self.fixed[i]:
                    p[i] = value
        room = np.where(np.isfinite(self.p_limit), self.p_limit, np.inf)
        p[free] = np.clip(p[free], 0.0, np.where(np.isfinite(room[free]), _TO_BOUND * room[free], np.inf))
        # a start beyond what a wall law (or a graded tube) reaches: halve it, then try the free
        # nodes at zero (the lowest pressures there: the fixed nodes' tubes then carry the most
        # flow and feel the least pressure downstream); failing that the fixed pressures alone
        # have no steady state
        for attempt in range(6):
            try:
                q, gu, gv, r_u, r_v = self._edges(p)
                break
            except NoSteadyStateError:
                if not np.any(p[free] > 0):
                    self._edges(p, named=True)
                    raise
                p[free] = 0.5 * p[free] if attempt < 4 else 0.0
        balance = self._balance(q, p)
        # nodes held at their bound (an active set): where Newton pushes a node into its limit
        # pressure and the line search must cut the step, the node is held there and the rest
        # solved; see _pinned_done
        pinned = np.zeros(len(self.nodes), dtype=bool)
        released = pinned.copy()          # (a node released once is not held again: no ping-pong)
        held_from = p.copy()              # a pinned node's pressure before it was held
        for iteration in range(max_iterations + 1):
            free = self.free
            F = balance[free]
            through = self._throughput(balance, p)
            worst = float(np.max(np.abs(F), initial=0.0))
            if worst <= rtol * through or through == 0.0 and worst == 0.0:
                if not np.any(pinned) or self._pinned_done(pinned, balance, p, rtol * through):
                    return self._result(p, q, r_u, r_v, iteration, worst / through if through else 0.0)
                # a pinned node takes flow out: its pressure goes down
                p, q, gu, gv, r_u, r_v, balance = self._release(p, pinned, released, held_from)
                continue
            if np.any(pinned) and np.linalg.norm(F) <= 10 * np.linalg.norm(self._noise(p, q, gu, gv)):
                # the rest balanced to what rounding allows (the held nodes' steep tubes amplify
                # it): the held nodes' excess decides now, where it dwarfs the rest's imbalance
                # (line searches stalled on rounding took tens of seconds to say the same)
                if not self._pinned_done(pinned, balance, p, max(rtol * through, 10 * float(np.sum(np.abs(F))))):
                    p, q, gu, gv, r_u, r_v, balance = self._release(p, pinned, released, held_from)
                    continue
            if iteration == max_iterations:
                break
            ju = np.maximum(np.nan_to_num(gu, nan=c, posinf=c / _CLIP), _CLIP * c)
            jv = -np.maximum(np.nan_to_num(-gv, nan=c, posinf=c / _CLIP), _CLIP * c)
            step = self._linear_solve(self._jacobian(ju, jv), -F)
            alpha, bounded = self._to_bound(p, step, released)
            if alpha == 0.0:
                # Newton's full steps brought the node to its limit pressure and push on: hold it
                # there (as a cut step into it would)
                pinned[bounded] = True
                held_from[bounded] = p[bounded]
                p = p.copy()
                p[bounded] = (1.0 - _AT_BOUND) * self.p_limit[bounded]
                self._unknowns(self.unknown & ~pinned)
                q, gu, gv, r_u, r_v = self._edges(p)
                balance = self._balance(q, p)
                continue
            first = alpha
            # the node a cut step would hold at its bound: within _NEAR_BOUND of it, never released
            pin = bounded if (bounded is not None and not released[bounded]
                              and self.p_limit[bounded] - p[bounded] <= _NEAR_BOUND * self.p_limit[bounded]) else None
            norm = float(np.linalg.norm(F))
            release = False
            while True:
                trial = p.copy()
                trial[free] = np.clip(p[free] + alpha * step, 0.0, None)
                try:
                    t_q, t_gu, t_gv, t_ru, t_rv = self._edges(trial)
                except NoSteadyStateError:    # beyond what a wall law reaches (a peak): shorter
                    t_balance = beyond = None
                else:
                    beyond = alpha
                    t_balance = self._balance(t_q, trial)
                if t_balance is not None and np.linalg.norm(t_balance[free]) <= (1 - 1e-4 * alpha) * norm:
                    break
                alpha *= 0.5
                if alpha < 1e-10 and pin is not None:
                    break                        # pushed into its bound without a better point: hold it there
                if alpha < 1e-10 and np.any(pinned):
                    # the rest stalls near its own bounds (rounding): the pinned nodes' excess
                    # still decides where it dwarfs the rest's imbalance
                    if not self._pinned_done(pinned, balance, p, max(rtol * through, 10 * float(np.sum(np.abs(F))))):
                        release = True
                        break
                # rounding alone: the imbalance within ten times what the pressures' rounding
                # leaves, as a whole (the norm the line search decreases: a node whose own noise is
                # small cannot be improved where its neighbours' rounding dwarfs it)
                if alpha < 1e-10 and norm <= 10 * float(np.linalg.norm(self._noise(p, q, gu, gv))) \
                        and _share(worst, through) <= _WORST_ROUNDED:
                    warn_user(f"network: mass balance to {_share(worst, through):.1e} of the throughput, not rtol = "
                              f"{rtol:g}: pressures close to a limit pressure amplify the rounding of the "
                              f"pressures into the flows beyond that", AccuracyWarning)
                    return self._result(p, q, r_u, r_v, iteration, _share(worst, through))
                if alpha < 1e-10 and beyond is None:
                    # every step, however short, leaves what a tube reaches (a graded tube whose
                    # profile would pass a section's limit pressure): Newton pushes beyond it
                    self._edges(trial, named=True)
                if alpha < 1e-10:
                    raise ConvergenceError(f"network: the line search stalled after {iteration} Newton iterations; "
                                           f"largest mass imbalance {worst:.3e} m^3/s = {_share(worst, through):.3e} of "
                                           f"the throughput (rtol {rtol:g}){_UNRESOLVED if through == 0 else ''}")
            if release:                 # a pinned node takes flow out: its pressure goes down
                p, q, gu, gv, r_u, r_v, balance = self._release(p, pinned, released, held_from)
                continue
            if pin is not None and alpha < first:
                # the step into the bound was cut: hold the node at its bound (to _AT_BOUND)
                if alpha < 1e-10:
                    trial = p.copy()
                pinned[pin] = True
                held_from[pin] = trial[pin]
                trial[pin] = (1.0 - _AT_BOUND) * self.p_limit[pin]
                self._unknowns(self.unknown & ~pinned)
                t_q, t_gu, t_gv, t_ru, t_rv = self._edges(trial)
                t_balance = self._balance(t_q, trial)
            p, q, gu, gv, r_u, r_v, balance = trial, t_q, t_gu, t_gv, t_ru, t_rv, t_balance
            if shown is not None:
                shown.update()
        raise ConvergenceError(f"network: no convergence in {max_iterations} Newton iterations; largest mass "
                               f"imbalance {worst:.3e} m^3/s = {_share(worst, through):.3e} of the throughput "
                               f"(rtol {rtol:g}){_UNRESOLVED if through == 0 else ''}")

    def _result(self, p, q, r_u, r_v, iterations, residual):
        if self.feed_groups.parts:
            at_u = self.feed_node == self.U
            other = np.where(at_u, self.V, self.U)
            p_in, r_in, r_out = self.feed_groups.inlet(np.where(self.feeder, q * np.where(at_u, 1.0, -1.0), 1.0),
                                                       p[other], self.tubes, at_u)
            p = p.copy()
            p[self.feed_node[self.feeder]] = p_in[self.feeder]
            r_u = np.where(self.feeder, np.where(at_u, r_in, r_out), r_u)
            r_v = np.where(self.feeder, np.where(at_u, r_out, r_in), r_v)
        for groups in (self.groups, self.feed_groups):
            groups.check(q, r_u, r_v, self.tubes, q >= 0)
        fluids = self.groups.fluids() + self.feed_groups.fluids()
        return NetworkSolution(net=self.net, nodes=self.nodes, tubes=self.tubes, p=p, q=q, radius_u=r_u,
                               radius_v=r_v, iterations=iterations, residual=residual, U=self.U, V=self.V,
                               radius0=self.radius0_u, radius0_v=self.radius0_v, length=self.length, fluids=fluids)

    def _noise(self, p, q, gu, gv):
        """Per free node, the mass imbalance that rounding alone leaves: the pressures' rounding
        through the tubes' conductances plus the flows' own relative accuracy (~1e-14)."""
        n = len(self.nodes)
        eps = np.finfo(float).eps
        per_tube = 4 * eps * (np.abs(gu * p[self.U]) + np.abs(gv * p[self.V])) + 1e-14 * np.abs(q)
        per_outlet = 4 * eps * self.g_out * (np.abs(p) + np.abs(self.p_distal))
        return (np.bincount(self.U, per_tube, n) + np.bincount(self.V, per_tube, n) + per_outlet)[self.free]

    def _throughput(self, balance, p):
        """The flow that enters the network: injections plus what the fixed nodes and the
        resistance outlets supply."""
        supplied = np.where(self.fixed, -balance, self._supplied(p))
        return float(np.sum(np.maximum(supplied, 0.0)))

    def _release(self, p, pinned, released, held_from):
        """Let the pinned nodes go, back to their pressures before they were held (Newton's
        iterate from the bound itself would start among enormous conductances); the new state."""
        p = p.copy()
        p[pinned] = held_from[pinned]
        released |= pinned
        pinned[:] = False
        self._unknowns(~self.fixed & ~self.feeds)
        q, gu, gv, r_u, r_v = self._edges(p)
        return p, q, gu, gv, r_u, r_v, self._balance(q, p)

    def _pinned_done(self, pinned, balance, p, tolerance):
        """At a solution of the other nodes with the ``pinned`` ones at their limit pressures:
        False where a pinned node takes flow out (a negative excess: its pressure goes down, so
        it is released); True where they balance (a steady state at the bound); raises where they
        keep an excess. Why that excess means no steady state: a tube's flow rises with its inlet
        pressure and falls with its outlet one, so raising some nodes' pressures to their limits
        raises every other free node's pressure, and with them what the fixed nodes and the
        resistance outlets take out; the free nodes' total excess can then only fall. A steady
        state below the limits would thus leave the pinned nodes' total excess <= 0."""
        excess = balance[pinned]
        if np.any(excess < -tolerance):
            return False
        if float(np.sum(excess)) <= tolerance:
            return True
        nodes = np.flatnonzero(pinned)
        i = int(nodes[np.argmax(excess)])
        tube = self._limiting_tube(i)
        # what the network did not carry out: the held nodes' excess and what the rest still
        # keeps (at rounding level where the rest is balanced to it)
        raise self._capacity_error(pinned, float(np.sum(excess) + np.sum(balance[self.free])), p, i, tube)

    def _capacity_error(self, pinned, excess, p, i, tube):
        r"""The NoSteadyStateError of inflows beyond the network's capacity, found with the nodes
        ``pinned`` held (to :data:`_AT_BOUND`) at their limit pressures and ``excess`` not carried
        out (left there and, at rounding level, at the other free nodes): its ``limit`` is the flow
        the network carries so, the injected flow less the excess
        (a lower bound on the capacity, the supremum over the pressures below the limits); the
        message adds an upper bound, the same with the tubes that leave the pinned nodes at their
        maximum flow rates (:func:`tubefsi.max_flow_rate` at their held outlet pressures: at the
        limit itself the other pressures can only be higher, and those flows lower)."""
        injected = float(np.sum(np.maximum(self.source, 0.0)))
        carried = injected - excess
        q, _, _, _, _ = self._edges(p)
        leaving = (pinned[self.U] & (q > 0)) | (pinned[self.V] & (q < 0))
        leaving &= ~(pinned[self.U] & pinned[self.V])
        room = float(np.sum(self._max_flow(p, leaving) - np.abs(q[leaving])))
        upper = (f"at most {carried + max(room, 0.0):.6g} m^3/s (the tubes leaving it at their maximum flow "
                 f"rates)" if np.isfinite(room) else "the fluid has no maximum flow rate in its tubes, so more "
                 "only in the limit, with tubes inflated beyond the model's range")
        return NoSteadyStateError("flow_rate", carried, injected,
                                  f"the network's capacity: with node {self.nodes[i]!r} held at the limit pressure "
                                  f"{self.p_limit[i]:.10g} Pa of tube {tube!r} (to {_AT_BOUND:g} relative) it "
                                  f"carries {carried:.6g} m^3/s of the {injected:.6g} m^3/s injected; {upper}",
                                  name="the injected flow rate")

    def _max_flow(self, p, mask):
        """Per tube of ``mask``, :func:`tubefsi.max_flow_rate` with its flow entering at its
        higher-pressure end and the other end's pressure as the outlet pressure."""
        forward = p[self.U] >= p[self.V]
        outlet = np.where(forward, p[self.V], p[self.U])
        out = np.zeros(int(np.sum(mask)))
        groups = _Groups(self.tubes, mask & ~self.feeder)
        feed = _Groups(self.tubes, mask & self.feeder)
        values = groups.max_flow(outlet, forward) + feed.max_flow(outlet, forward)
        out[:] = values[mask]
        return out

    def _to_bound(self, p, step, released):
        """The largest step fraction (<= 1) that goes at most 90 % of the way to a bound, and the
        node whose limit pressure sets it (None where none does); where a node sits at its limit
        pressure (to _AT_BOUND) and the step still pushes outward, ``(0.0, node)`` (the caller holds
        it there) or, for a node held and ``released`` before, raises."""
        pf, lim = p[self.free], self.p_limit[self.free]
        up = step > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            gap_up = np.where(up, lim - pf, np.inf)
            gap_down = np.where(~up, pf, np.inf)
            frac = np.where(up, _TO_BOUND * gap_up / step, _TO_BOUND * gap_down / -step)
        frac = np.where(step == 0, np.inf, frac)
        i = int(np.argmin(frac))
        if frac[i] >= 1:
            return 1.0, None
        node = int(self.free[i])
        if up[i] and gap_up[i] <= _AT_BOUND * lim[i]:
            if not released[node]:
                return 0.0, node
            tube = self._limiting_tube(node)
            raise NoSteadyStateError("pressure", float(lim[i]), float(pf[i]),
                                     f"tube {tube!r} reaches its limit pressure at node {self.nodes[node]!r} "
                                     f"(to {_AT_BOUND:g} relative): no steady state below it carries these inflows")
        if not up[i] and gap_down[i] <= _AT_BOUND * max(float(np.max(p)), 1e-300):
            raise InvalidParameterError("inflow", "inflows that keep every pressure >= 0 (tubefsi models "
                                        "inflation, not collapse)", self.nodes[node],
                                        f"node {self.nodes[node]!r} would need a negative transmural pressure")
        return float(frac[i]), (node if up[i] else None)


class _Pattern:
    """The sparsity pattern of the Jacobian over a solver's unknowns, in compressed-column form,
    built once per set of unknowns: an entry of :meth:`_Solver._jacobian`'s value list (the tubes'
    four derivatives and the outlets' diagonal) either falls outside the unknowns (dropped) or
    adds into one slot of the matrix's data (duplicates, such as the diagonal, add up). With
    ``order`` (a permutation of the free nodes, from a first factorization) free node ``i`` sits
    at row and column ``order[i]``; ``inverse`` is the free node at each position."""

    def __init__(self, solver, order):
        U, V = solver.U, solver.V
        outlets = np.flatnonzero(solver.g_out)
        rows = np.concatenate([U, U, V, V, outlets])
        cols = np.concatenate([U, V, U, V, outlets])
        self.keep = solver.unknown[rows] & solver.unknown[cols]
        m = self.m = solver.free.size
        r, c = solver.where[rows[self.keep]], solver.where[cols[self.keep]]
        self.order = None if order is None else np.asarray(order)
        if order is None:              # (one matrix before the ordering: SciPy sums it from COO)
            self.rows, self.cols = r, c
            return
        r, c = self.order[r], self.order[c]
        self.inverse = np.argsort(self.order)
        # column-major keys: their sorted distinct values are the matrix's entries in CSC order
        keys, self.slot = np.unique(c.astype(np.int64) * m + r, return_inverse=True)
        self.indices = (keys % m).astype(np.int32)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(keys // m, minlength=m))]).astype(np.int32)

    def matrix(self, values):
        """The CSC matrix of the pattern with the entries ``values`` (summed into their slots)."""
        if self.order is None:
            return sp.csc_matrix((values[self.keep], (self.rows, self.cols)), shape=(self.m, self.m))
        data = np.bincount(self.slot, values[self.keep], self.indices.size)
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(self.m, self.m))


#: Why a network can have no resolvable throughput: tubes in series whose conductances differ by
#: more than double precision resolves (the drop over the wide one is below one rounding unit of
#: the pressures, so its flow is either 0 or far too large).
_UNRESOLVED = ("; no flow is resolved at all: tubes in series whose conductances differ beyond double "
               "precision (e.g. radii 5 m and 0.1 mm) cannot balance; model the wide one as a node")


#: The largest mass imbalance (a share of the throughput) accepted, with an AccuracyWarning, where
#: the rounding of the pressures allows no better; beyond it the line search's stall is an error.
_WORST_ROUNDED = 1e-4


def _at(index, by_node):
    """``(positions, values)`` of a mapping node -> value (a number or a pair): the nodes'
    positions in ``index`` and their values as an array."""
    at = np.fromiter(map(index.__getitem__, by_node), np.intp, len(by_node))
    return at, np.array(list(by_node.values()), dtype=float)


def _share(worst, through) -> float:
    """The imbalance as a share of the throughput (inf where nothing flows but something should)."""
    return worst / through if through > 0 else (0.0 if worst == 0 else float("inf"))
