"""Rational-ratio resampling in blocks (scipy ``resample_poly``), bounded memory."""

from __future__ import annotations

from collections.abc import Iterable
from math import gcd

import numpy as np

BLOCK = 1 << 20  # input samples per block


def resample_poly(x: np.ndarray, up: int, down: int) -> np.ndarray:
    """scipy's ``resample_poly``, imported on first use: scipy.signal takes most of a
    second to import, which a command's usage error need not wait for."""
    from scipy.signal import resample_poly as poly

    return poly(x, up, down)


def _plan(rate_in: int, rate_out: int) -> tuple[int, int, int, int]:
    """(up, down, margin, block): the ratio, the filter's reach and the block, in input
    samples, both whole input periods (so every block starts in the same filter phase)."""
    g = gcd(int(rate_in), int(rate_out))
    up, down = int(rate_out) // g, int(rate_in) // g
    # filter half length (scipy default: 10 * max(up, down) taps at the upsampled rate)
    margin = -(-10 * max(up, down) // up) + 2
    margin = -(-margin // down) * down
    return up, down, margin, max(BLOCK // down, 1) * down


def resample(samples: np.ndarray, rate_in: int, rate_out: int) -> np.ndarray:
    """Resample mono float32 ``samples`` from ``rate_in`` to ``rate_out`` Hz.

    Works block by block with a margin covering the anti-alias filter, so the result equals
    one ``resample_poly`` call to float precision while memory stays one block plus output.
    """
    x = np.asarray(samples, dtype=np.float32)
    if rate_in == rate_out or x.size == 0:
        return x.copy()
    up, down, margin, block = _plan(rate_in, rate_out)
    n_out = -(-x.size * up // down)
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


def resample_blocks(blocks: Iterable[np.ndarray], rate_in: int, rate_out: int, *,
                    size_hint: int = 0) -> tuple[np.ndarray, int]:
    """:func:`resample` of the concatenated mono float32 ``blocks``, and their length.

    The same ``resample_poly`` calls on the same input stretches, so the same samples,
    while only one resampling block (plus its margins) of the input is held; ``size_hint``
    (the expected input length) sizes the result up front. Blocks may be reused buffers.
    """
    up, down, margin, block = _plan(rate_in, rate_out)
    out = np.empty(-(-max(int(size_hint), 0) * up // down), dtype=np.float32)
    n_out = 0  # output samples written

    def put(y: np.ndarray) -> None:
        nonlocal out, n_out
        if n_out + y.size > out.size:
            out = np.resize(out, max(2 * out.size, n_out + y.size))
        out[n_out:n_out + y.size] = y
        n_out += y.size

    if up == down:
        n = 0
        for b in blocks:
            put(np.asarray(b, dtype=np.float32))
            n += b.size
        return out[:n_out], n
    held = np.empty(block + 2 * margin + (1 << 16), dtype=np.float32)
    base = 0  # input index of held[0]
    have = 0  # samples in held
    start = 0  # input index of the next block to resample
    whole = block + 2 * margin  # longer inputs go block by block (as in ``resample``)

    def emit(stop: int, size: int | None) -> None:
        """Resample block ``start .. stop`` (``size``: the input's length, if known)."""
        nonlocal start
        lo = max(0, start - margin)
        hi = stop + margin if size is None else min(size, stop + margin)
        y = resample_poly(held[lo - base:hi - base], up, down)
        skip = (start - lo) * up // down
        o0 = start * up // down
        o1 = -(-size * up // down) if stop == size else stop * up // down
        put(y[skip:skip + (o1 - o0)].astype(np.float32, copy=False))
        start = stop

    for b in blocks:
        k = b.size
        if have + k > held.size:
            held = np.resize(held, have + k)  # blocks larger than planned for
        held[have:have + k] = b
        have += k
        while base + have > whole and base + have >= start + block + margin:
            emit(start + block, None)
            drop = max(0, start - margin) - base  # what no later block reads
            held[:have - drop] = held[drop:have]  # numpy copies overlaps safely
            base += drop
            have -= drop
    size = base + have
    if size == 0:
        return out[:0], 0
    if size <= whole:  # one call over the whole input, as ``resample`` does
        put(resample_poly(held[:have], up, down).astype(np.float32, copy=False)
            [:-(-size * up // down)])
        return out[:n_out], size
    while start < size:
        emit(min(start + block, size), size)
    return out[:n_out], size
