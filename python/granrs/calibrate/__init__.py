"""Calibration: fit the force law's coefficients (and the leg's joints) to measurements.

The thesis tuned its coefficients by hand, one angle at a time (sec. 3.3.1, Table 3.4), and
concludes that its simulated stopping times disagree with the experiments even where the
depths match (Figs. 3.15-3.20). :func:`calibrate` does the tuning as a weighted least squares
fit instead: given measured depths and stopping times with their spread
(:class:`Measurements`), it finds the chosen parameters that minimise

    sum over rows and quantities of ((simulated - measured mean) / sd_fit)^2,

with :func:`scipy.optimize.least_squares` (trust-region reflective, with bounds), and
reports the fitted values, their standard errors and ~95 % intervals, the residuals of every
row in units of the measured sd, and what the fit cost (simulations and seconds).

Every residual evaluation runs all rows in one :func:`granrs.sweep` call (a list of scenes,
run in parallel in the Rust core), and the forward-difference Jacobian puts the scenes of
all p + 1 parameter vectors (the point and one step per parameter) in one sweep as well.

Parameters (``params``), by name:

* ``TERM.PARAM``: any parameter of any term of the law (``static_v.eta_v``, ``drag.eta_d``,
  ``poncelet.c``, ``rft.zeta``, ...; the names of :mod:`granrs.forces` and each term's
  ``.info.params``): one value for every row (both links of the chain, both speeds of the
  leg). The thesis's short names ``eta_h``, ``eta_d``, ``eta_v``, ``lam`` (``lambda`` is
  accepted) are ``static_h.eta_h``, ``drag.eta_d``, ``static_v.eta_v``, ``static_v.lam``;
* ``eta_v@45``, ``static_v.eta_v@45`` (any parameter, any angle in degrees, free link
  only): the parameter at the angle node q = 45 deg; a row at another angle takes the value
  interpolated between the nodes on either side (linearly in q: in log for a parameter
  fitted in log space, plainly for lambda; constant beyond the outermost nodes). Nodes at
  the measured angles are per-angle coefficients, as Table 3.4 tabulates them;
  ``per_angle=True`` makes them from plain names;
* ``scale.eta_v``, ``scale.TERM.PARAM``: a factor on the base value of every row (``base``:
  Table 3.4's nearest row or the Table 3.2 closed forms for the free link, Table 4.4 per
  link and case for the chain, the thesis's row of sec. 5.3.2 for the leg; or the terms
  given as ``forces``), so that the shape in angle (or link, or speed) of the base is kept;
* the body's unknowns: ``mass`` [kg] (the link mass: the chain's is not in the thesis),
  ``pin_mass`` [kg] (chain), ``joints.k`` [N m/rad] and ``joints.c`` [N m s/rad] (leg: one
  rotational spring-damper at the ankle, knee and hip).

The law is the thesis's (its terms built from ``base``'s coefficients) unless ``forces``
gives the terms: a list for every row, or a function of the row. A fitted parameter of a
term the law does not list is an error before any simulation.

A term's parameter whose registry minimum is >= 0 (the etas, ``poncelet.c``, ...), the
scale factors, the masses and the joint settings are positive and fitted in log space;
lambda (an exponent, which may be 0) and any parameter allowed below 0 are fitted as they
are. Bounds are given in natural units.

Weights. Each quantity's sd in the fit is ``sd_fit = sqrt(sd^2 + resolution^2 / 12)``: the
measured sd and, in quadrature, the rounding of the printed mean (uniform over one unit of
the last printed digit). The thesis prints depths and stopping times to the millimetre and
the millisecond, so :meth:`Measurements.thesis` sets ``resolution`` = 0.001 m and 0.001 s
(0.29 mm and 0.29 ms in quadrature: a few % on the typical sd of 1-3, and what keeps the
weight finite where Table 5.1 prints an sd of 0.000). A user CSV has no rounding term
unless asked. The counts "within k sd" that the report quotes use the measured sd alone
(``*_z`` columns of the residuals), so the rounding term never makes a count look better.

Uncertainty. The standard errors come from the Jacobian at the optimum: the covariance of
the fitted (transformed) parameters is (J^T J)^-1 with J the Jacobian of the weighted
residuals (J^T W J of the unweighted ones), multiplied by the reduced chi-square when that is
above 1 (``error_scale="auto"``: a misfitting model widens the intervals, a good one does not
shrink them). The ~95 % interval is +-1.96 standard errors in the fitted space, mapped back
(so asymmetric for a log-space parameter). A parameter that ends on a bound has no reliable
interval; it is listed in :attr:`CalibrationResult.at_bound`.

Finite differences. The stopping time and the depth are located on the step's interpolant
(dt = 1e-4), so they are continuous in the parameters, but the sign modes of the static
terms and the event search add round-off-level noise (about 1e-9 s, 1e-9 m here). The
default step, a relative 1e-3 (``rel_step``), changes t_s by ~1e-6 s, a thousand times the
noise, while the truncation error of a forward difference at that step is ~1e-3 of the
derivative; see ``tests/test_calibrate.py`` for the check.
"""

from __future__ import annotations

from .fit import CalibrationResult, calibrate, evaluate, within
from .measurements import BODIES, QUANTITIES, THESIS_MEASUREMENTS, Measurements
from .posterior import Posterior

__all__ = [
    "BODIES",
    "QUANTITIES",
    "THESIS_MEASUREMENTS",
    "CalibrationResult",
    "Measurements",
    "Posterior",
    "calibrate",
    "evaluate",
    "within",
]
