r"""Independent references for tubefsi's tests, benchmarks and examples.

Nothing in this subpackage calls tubefsi's numerics, and no module in it imports tubefsi
(importing ``tubefsi.testing.reference`` initialises its parent packages, as any Python import
does, but nothing here uses them). Everything is written afresh from the physics of
``docs/theory.md`` — the tube laws of section "Tube laws", the flow laws of section "The flow law
of a generalized Newtonian fluid" and the separation of variables of section "Coupling without
an ODE" — so that a test comparing tubefsi against it measures tubefsi's error alone. Where an
argument is one of tubefsi's objects (a ``Tube`` in :mod:`.chapter_baseline`) it is only read
through its attributes (duck typing), so no tubefsi type is needed.

The mpmath modules work at whatever ``mp.dps`` the caller sets (the tests use 30 to 60 digits,
through ``mp.workdps``) and never change the global precision. They need ``mpmath``, which is in
the ``test`` extra; ``tubefsi.testing`` does not import this subpackage, so ``import
tubefsi.testing`` does not need mpmath. Import the modules directly:

* :mod:`.tube_laws` — one reference wall, :class:`~.tube_laws.RefWall`, for every wall theory
  (thick Lamé, thin with the reference or the current thickness, thin and thick linear): the
  closed-form laws of the built-in neo-Hookean and Mooney–Rivlin walls with hand-derived
  slopes, and the laws of any material given by its three-dimensional strain energy
  (neo-Hookean, Mooney–Rivlin, Gent, Demiray, Yeoh, Ogden, Arruda–Boyce) by quadrature and Leibniz's rule; the
  table :data:`~.tube_laws.WALLS` of the built-in walls the accuracy tests use; the stretch at a
  given pressure; :class:`~.tube_laws.HoopFibre`, a strain-stiffening user law (a neo-Hookean
  matrix with circumferential exponential fibres) written as the wall-law tutorial teaches.
* :mod:`.power_law` — power-law flow (Newtonian included) in such a wall, separated:
  :math:`\phi(q)` and its inverse, :math:`\hat J(\lambda) = \int_1^\lambda P'(s)s^k ds` (by parts,
  in :math:`\ln s`, or directly), its tail, :math:`J_\infty` and the maximum flow rate for limit
  walls, the inlet stretch of a flow rate, and flow-controlled cases at the double flow rates of
  given inlet stretches.
* :mod:`.rheology` — generalized Newtonian flow (Carreau–Yasuda, and any law given by its shear
  rate, yield stress included) in a reference wall, through the Rabinowitsch–Mooney integral
  parametrized by the wall shear rate or stress; velocity profiles; the yield pressure drop.
* :mod:`.quadrature` — the geometric break points and the fixed Gauss–Legendre rule the others use.
* :mod:`.chapter_baseline` — the chapter's own method (``scipy.integrate.odeint`` at its default
  tolerances, one ODE per flow rate, a lean scalar right-hand side), the baseline of the speed
  ratios in ``benchmarks/speed.py`` and ``examples/work_precision.py``. It needs scipy, not
  mpmath.

:func:`rel_err` compares a library result with a reference value.
"""

from __future__ import annotations

__all__ = ["rel_err"]


def rel_err(got, ref) -> float:
    """``|got - ref| / |ref|`` as a float, computed at the current ``mp.dps``.

    ``got`` is a library result (a float, a NumPy scalar or 0-d array: converted through
    ``float`` exactly) or an mpmath number (used as it is); ``ref`` an mpmath number or a float.
    """
    from mpmath import mpf

    if not isinstance(got, mpf):
        got = mpf(float(got))
    return float(abs((got - ref) / ref))
