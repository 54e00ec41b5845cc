"""Gaussian posteriorgrams: frames as posteriors over sound classes learnt from the
recording itself."""

from __future__ import annotations

import numpy as np

from speechcal_core.speech.posteriorgram import fit_mixture, gaussian_posteriorgram


def two_clusters(n: int = 400, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Frames drawn around two far-apart centres, and which centre each came from."""
    rng = np.random.default_rng(seed)
    which = rng.integers(0, 2, n)
    centres = np.array([[-3.0] * 4, [3.0] * 4])
    return centres[which] + rng.standard_normal((n, 4)), which


def test_em_learns_two_well_separated_classes() -> None:
    x, which = two_clusters()
    model = fit_mixture(x, components=2, seed=1)
    assigned = model.posteriors(x).argmax(axis=1)
    agree = np.mean(assigned == which)
    assert max(agree, 1.0 - agree) > 0.99  # the same split, whichever label each got
    assert np.allclose(np.sort(model.weights), [0.5, 0.5], atol=0.1)


def test_rows_have_unit_length_so_the_dtw_cosine_compares_posteriors() -> None:
    x, _ = two_clusters()
    gram = gaussian_posteriorgram(x, components=8, mixtures=3)
    assert gram.shape == (x.shape[0], 24)
    assert np.allclose(np.linalg.norm(gram, axis=1), 1.0, atol=1e-5)
    assert np.all(gram > 0.0)  # floored: no frame is certain of one class


def test_frames_of_one_class_are_closer_than_frames_of_two() -> None:
    x, which = two_clusters()
    gram = gaussian_posteriorgram(x, components=8)
    same = 1.0 - gram[which == 0][:50] @ gram[which == 0][50:100].T
    other = 1.0 - gram[which == 0][:50] @ gram[which == 1][:50].T
    assert np.median(same) < 0.3 < 0.8 < np.median(other)


def test_the_same_frames_give_the_same_posteriorgram() -> None:
    x, _ = two_clusters()
    assert np.array_equal(gaussian_posteriorgram(x), gaussian_posteriorgram(x))


def test_no_frames_give_an_empty_posteriorgram() -> None:
    assert gaussian_posteriorgram(np.zeros((0, 12))).shape[0] == 0
