"""The numerics layer shared by walls, rheologies and couplers (layer 0: imports only NumPy and
:mod:`tubefsi.errors`).

================  ===========================================================================
module            contents
================  ===========================================================================
``kernels``       small vectorized kernels: stable ``expm1``/``log1p`` ratios, Gauss–Legendre
                  rules, row products, float-or-array outputs
``quadrature``    the one adaptive Gauss–Kronrod loop (plain, robust for kinks, graded toward a
                  pole or toward 0), its :class:`~tubefsi.numerics.quadrature.Integral` result,
                  and fixed composite rules for coarse couplers
``chebyshev``     the one table stack: piecewise polynomial interpolants with a-posteriori
                  checks, evaluated on arrays or on one float
``spectral``      the one-batch solution of :math:`\\int_0^x f = T` from a Chebyshev interpolant
``roots``         safeguarded Newton iterations on many points at once
================  ===========================================================================

Nothing here holds state between calls: every result is returned, with its error estimate, and
the caller decides whether a miss is an :class:`~tubefsi.AccuracyWarning`.
"""
