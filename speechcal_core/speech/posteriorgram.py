"""Gaussian posteriorgrams: each feature frame as its posterior over the components of
mixture models trained, without labels, on the recording's own speech.

A frame's posterior says which of the recording's sound classes it resembles, not its
exact spectrum, so it varies less with the speaker and with the noise than the features
it comes from (Zhang and Glass, "Unsupervised spoken keyword spotting via segmental DTW on
Gaussian posteriorgrams", 2009). Each row holds the square roots of the posteriors of
several mixtures, scaled so the row has unit length: the cosine distance of two rows is
one minus the mean Bhattacharyya coefficient of their posteriors, and the DTW of
``query_by_example`` compares them unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

COMPONENTS = 32
#: mixtures with different starting points; their posteriors are averaged (one mixture's
#: result depends much on where its EM starts)
MIXTURES = 3
EM_ITERATIONS = 25
MAX_TRAINING_FRAMES = 20000  # a random subset trains the mixtures of long recordings
MIN_VARIANCE = 0.05  # of normalised features: no component collapses onto a few frames
POSTERIOR_FLOOR = 1e-3  # added to every posterior: a frame is never certain of a class
CHUNK_FRAMES = 50000  # posteriors of long recordings are computed in parts of this many


@dataclass(frozen=True)
class DiagonalMixture:
    """A Gaussian mixture with diagonal covariances."""

    means: np.ndarray  # components x dims
    variances: np.ndarray  # components x dims
    weights: np.ndarray  # components

    def log_likelihoods(self, x: np.ndarray) -> np.ndarray:
        """Log weight plus log density of each frame (rows of ``x``) per component."""
        inv = 1.0 / self.variances
        quad = (x * x) @ inv.T - 2.0 * x @ (self.means * inv).T \
            + np.sum(self.means * self.means * inv, axis=1)
        norm = np.sum(np.log(self.variances), axis=1) + x.shape[1] * np.log(2 * np.pi)
        return np.log(self.weights) - 0.5 * (quad + norm)

    def posteriors(self, x: np.ndarray) -> np.ndarray:
        """Each frame's posterior over the components (rows sum to one)."""
        ll = self.log_likelihoods(x)
        p = np.exp(ll - ll.max(axis=1, keepdims=True))
        return p / p.sum(axis=1, keepdims=True)


def fit_mixture(x: np.ndarray, components: int, seed: int,
                iterations: int = EM_ITERATIONS) -> DiagonalMixture:
    """A diagonal mixture fitted to the rows of ``x`` by EM, started at random frames."""
    rng = np.random.default_rng(seed)
    k = min(components, x.shape[0])
    variance = np.maximum(x.var(axis=0), MIN_VARIANCE)
    model = DiagonalMixture(x[rng.choice(x.shape[0], k, replace=False)].astype(np.float64),
                            np.tile(variance, (k, 1)), np.full(k, 1.0 / k))
    for _ in range(iterations):
        p = model.posteriors(x)
        mass = p.sum(axis=0) + 1e-9
        means = (p.T @ x) / mass[:, None]
        variances = np.maximum((p.T @ (x * x)) / mass[:, None] - means * means, MIN_VARIANCE)
        model = DiagonalMixture(means, variances, mass / mass.sum())
    return model


def gaussian_posteriorgram(feats: np.ndarray, components: int = COMPONENTS,
                           mixtures: int = MIXTURES, seed: int = 0) -> np.ndarray:
    """Unit-length rows of square-root posteriors of ``feats`` (normalised features, one
    frame per row) under ``mixtures`` mixtures trained on those frames; the same input
    and seed give the same output."""
    n = feats.shape[0]
    if n == 0:
        return np.zeros((0, mixtures * components), dtype=np.float32)
    x = np.asarray(feats, dtype=np.float64)
    rng = np.random.default_rng(seed)
    train = x if n <= MAX_TRAINING_FRAMES else x[rng.choice(n, MAX_TRAINING_FRAMES,
                                                            replace=False)]
    models = [fit_mixture(train, components, seed=seed + 1 + m) for m in range(mixtures)]
    out = np.empty((n, sum(m.weights.size for m in models)), dtype=np.float32)
    for a in range(0, n, CHUNK_FRAMES):
        parts = []
        for model in models:
            p = model.posteriors(x[a:a + CHUNK_FRAMES]) + POSTERIOR_FLOOR
            parts.append(np.sqrt(p / p.sum(axis=1, keepdims=True) / mixtures))
        out[a:a + CHUNK_FRAMES] = np.hstack(parts)
    return out
