"""Rational-ratio resampling in blocks (scipy ``resample_poly``), bounded memory."""

from __future__ import annotations

from math import gcd

import numpy as np
from scipy.signal import resample_poly

BLOCK = 1 << 20  # input samples per block


def resample(samples: np.ndarray, rate_in: int, rate_out: int) -> np.ndarray:
    """Resample mono float32 ``samples`` from ``rate_in`` to ``rate_out`` Hz.

    Works block by block with a margin covering the anti-alias filter, so the result equals
    one ``resample_poly`` call to float precision while memory stays one block plus output.
    """
    x = np.asarray(samples, dtype=np.float32)
    if rate_in == rate_out or x.size == 0:
        return x.copy()
    g = gcd(int(rate_in), int(rate_out))
    up, down = int(rate_out) // g, int(rate_in) // g
    n_out = -(-x.size * up // down)
    # filter half length (scipy default: 10 * max(up, down) taps at the upsampled rate)
    margin = -(-10 * max(up, down) // up) + 2
    margin = -(-margin // down) * down
    block = max(BLOCK // down, 1) * down
    if x.size <= block + 2 * margin:
        return resample_poly(x, up, down).astype(np.float32, copy=False)[:n_out]
    out = np.empty(n_out, dtype=np.float32)
    for start in range(0, x.size, block):
        stop = min(start + block, x.size)
        lo, hi = max(0, start - margin), min(x.size, stop + margin)
        y = resample_poly(x[lo:hi], up, down)
        skip = (start - lo) * up // down
        o0 = start * up // down
        o1 = n_out if stop == x.size else stop * up // down
        out[o0:o1] = y[skip:skip + (o1 - o0)]
    return out
