"""Posterior samples of a calibration: emcee's affine-invariant ensemble sampler (Foreman-Mackey
et al., PASP 125 (2013) 306) on the fit's parameters.

The likelihood is the fit's own: Gaussian residuals over each row's sd (the measured sd with
the printed means' rounding added in quadrature, :meth:`Measurements.sd_fit`), taken as
known, so that log p = -chi2 / 2. The prior is uniform within the fit's bounds in the fitted
space: in the logarithm for a positive parameter (a scale-free prior), plainly for lambda.
The walkers start in a ball about the least-squares optimum drawn from its covariance (the
Laplace approximation), each proposal of half the walkers runs as one sweep, and the first
half of every chain is dropped as burn-in.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidParameterError

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Posterior"]


@dataclass(frozen=True)
class Posterior:
    """Posterior samples of a calibration's parameters (:func:`granrs.calibrate` with
    ``posterior=``).

    Attributes:
        samples: one column per parameter in natural units, one row per sample (every
            walker's chain after the burn-in, thinned by ``thin``).
        walkers: the ensemble's walkers; ``steps`` each, of which ``burn`` were dropped.
        acceptance: the mean acceptance fraction (emcee's guide: about 0.2 to 0.5).
        autocorr: the integrated autocorrelation time of each parameter's chain [steps]
            (emcee's estimate); a chain shorter than 50 of them gives a rough one, and
            ``converged`` is then False.
        converged: whether every chain after the burn-in is longer than 50 autocorrelation
            times (emcee's rule of thumb for a reliable estimate).
        log_prob: the log posterior of each sample (up to a constant).
    """

    samples: pd.DataFrame
    walkers: int
    steps: int
    burn: int
    thin: int
    acceptance: float
    autocorr: dict[str, float]
    converged: bool
    log_prob: np.ndarray = field(repr=False)

    def interval(self, level: float = 0.9) -> dict[str, tuple[float, float]]:
        """The central credible interval of each parameter holding ``level`` of the
        posterior (0.9: the 5th to the 95th percentile)."""
        if not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
            raise InvalidParameterError(f"level must be in (0, 1); got {level!r}", field="level")
        lo, hi = 50.0 * (1.0 - level), 50.0 * (1.0 + level)
        return {
            p: (float(np.percentile(v, lo)), float(np.percentile(v, hi)))
            for p, v in self.samples.items()
        }


def sample(
    evaluate: Callable[[Sequence[np.ndarray]], np.ndarray],
    to_natural: Callable[[np.ndarray], np.ndarray],
    names: Sequence[str],
    x_opt: np.ndarray,
    cov: np.ndarray,
    box: tuple[np.ndarray, np.ndarray],
    steps: int,
    walkers: int | None,
    seed: int,
) -> Posterior:
    """Run the ensemble from a ball about ``x_opt`` (fitted space) for ``steps`` steps;
    ``evaluate`` gives the weighted residuals of a list of points in one sweep."""
    import emcee
    import pandas as pd

    lo_x, hi_x = box
    ndim = len(x_opt)
    n_walkers = walkers if walkers is not None else max(8, 4 * ndim)
    rng = np.random.default_rng(seed)

    def log_prob(xs: np.ndarray) -> np.ndarray:
        xs = np.atleast_2d(xs)
        inside = np.all((xs >= lo_x) & (xs <= hi_x), axis=1)
        out = np.full(len(xs), -np.inf)
        if np.any(inside):
            r = evaluate(list(xs[inside]))
            out[inside] = -0.5 * np.sum(r * r, axis=1)
        return out

    start = _ball(rng, x_opt, cov, lo_x, hi_x, n_walkers)
    sampler = emcee.EnsembleSampler(n_walkers, ndim, log_prob, vectorize=True)
    # Seeded: the sampler draws its moves from a RandomState of its own.
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    sampler.run_mcmc(start, steps, progress=False)
    burn = steps // 2
    thin = 1
    chain = sampler.get_chain(discard=burn, thin=thin, flat=True)
    lp = sampler.get_log_prob(discard=burn, thin=thin, flat=True)
    tau = sampler.get_autocorr_time(discard=burn, quiet=True, tol=0)
    natural = np.array([to_natural(x) for x in chain])
    samples = pd.DataFrame(natural, columns=list(names))
    autocorr = {n: float(t) for n, t in zip(names, np.atleast_1d(tau), strict=True)}
    converged = bool(np.all(np.isfinite(tau)) and (steps - burn) > 50 * float(np.max(tau)))
    return Posterior(
        samples=samples,
        walkers=n_walkers,
        steps=steps,
        burn=burn,
        thin=thin,
        acceptance=float(np.mean(sampler.acceptance_fraction)),
        autocorr=autocorr,
        converged=converged,
        log_prob=lp,
    )


def _ball(
    rng: np.random.Generator,
    x_opt: np.ndarray,
    cov: np.ndarray,
    lo_x: np.ndarray,
    hi_x: np.ndarray,
    n: int,
) -> np.ndarray:
    """``n`` starting points about the optimum from the Laplace covariance (a small ball
    where it is not finite), inside the box."""
    ndim = len(x_opt)
    spread = np.full(ndim, 1e-3)
    ok = np.all(np.isfinite(cov)) and np.all(np.linalg.eigvalsh(0.5 * (cov + cov.T)) > 0)
    if ok:
        pts = rng.multivariate_normal(x_opt, cov, size=n)
    else:
        pts = x_opt + spread * rng.standard_normal((n, ndim))
    width = hi_x - lo_x
    return np.clip(pts, lo_x + 1e-9 * width, hi_x - 1e-9 * width)


def check_options(posterior: Any, walkers: Any, n_params: int) -> None:
    """The sampler's options, refused before any run (``field`` names them)."""
    if isinstance(posterior, bool) or not isinstance(posterior, int) or posterior < 0:
        raise InvalidParameterError(
            f"posterior must be a number of steps >= 0 (0: none); got {posterior!r}",
            field="posterior",
        )
    if 0 < posterior < 20:
        raise InvalidParameterError(
            f"posterior: {posterior} steps are too few for a chain (at least 20, of which "
            "the first half is burn-in)",
            field="posterior",
        )
    if walkers is not None and (
        isinstance(walkers, bool)
        or not isinstance(walkers, int)
        or walkers < 2 * n_params
        or walkers % 2
    ):
        raise InvalidParameterError(
            f"walkers must be an even number >= 2 x the parameters ({2 * n_params}); "
            f"got {walkers!r}",
            field="walkers",
        )


def predictive(
    simulate: Callable[[Sequence[Sequence[float]]], tuple[np.ndarray, np.ndarray]],
    posterior: Posterior,
    draws: int,
    level: float,
    seed: int,
) -> Mapping[str, np.ndarray]:
    """The predictive interval of depth and t_s per row: the simulated values at ``draws``
    posterior samples (one sweep), their central ``level`` interval and median."""
    rng = np.random.default_rng(seed)
    k = min(draws, len(posterior.samples))
    rows = rng.choice(len(posterior.samples), size=k, replace=False)
    vectors = posterior.samples.to_numpy()[rows]
    depth, t_s = simulate(vectors)
    lo, hi = 50.0 * (1.0 - level), 50.0 * (1.0 + level)
    out: dict[str, np.ndarray] = {}
    for q, v in (("depth", depth), ("t_s", t_s)):
        out[f"{q}_median"] = np.nanmedian(v, axis=0)
        out[f"{q}_lo"] = np.nanpercentile(v, lo, axis=0)
        out[f"{q}_hi"] = np.nanpercentile(v, hi, axis=0)
    return out
