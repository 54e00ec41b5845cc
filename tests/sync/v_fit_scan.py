"""The V fit as a least-squares solve per grid vertex: the reference the batched fit meets."""

from __future__ import annotations

import numpy as np


def scan_vertices(x: np.ndarray, y: np.ndarray, t_min: float,
                  period: float) -> tuple[float | None, float]:
    """Best vertex of the grid ``_fit_v`` searches, by one ``np.linalg.lstsq`` per vertex,
    and its squared residual (None, inf when no vertex gives closing < 0 < opening)."""
    grid = np.arange(t_min - 0.25 - period, t_min + 0.25 + period, 2.5e-4)
    best, best_err = None, np.inf
    for tc in grid:
        if (x < tc).sum() < 2 or (x > tc).sum() < 1:
            continue
        err, coef = vertex_fit(x, y, float(tc))
        if coef[1] < 0 < coef[2] and err < best_err:
            best, best_err = float(tc), err
    return best, best_err


def vertex_fit(x: np.ndarray, y: np.ndarray, tc: float) -> tuple[float, np.ndarray]:
    """Squared residual and coefficients (level, closing, opening) of the V at ``tc``."""
    basis = np.stack([np.ones_like(x), np.minimum(x - tc, 0.0), np.maximum(x - tc, 0.0)],
                     axis=1)
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(np.sum((basis @ coef - y) ** 2)), coef
