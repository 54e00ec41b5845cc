"""The speech index: features of the voice-active frames only, read back by time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from speech_scenes import make_scene

from speechcal_core.speech.features import HOP_S
from speechcal_core.speech.speech_index import SpeechIndex


def test_a_span_holds_the_active_frames_rows_and_zeros_between(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "two.wav", [("capture", "rms/capture_1"),
                                              ("okay", "rms/okay_1")], gap_s=1.5)
    index = SpeechIndex.build(scene.samples, 16000)
    (a, _), (_, b) = scene.spans("capture")[0], scene.spans("okay")[0]
    rows = index.span(a - 0.3, b + 0.3)
    first = int((a - 0.3) / HOP_S)
    active = np.isin(np.arange(first, first + rows.shape[0]), index.frames)
    assert rows.shape == (int((b + 0.3) / HOP_S) - first, index.seq.shape[1])
    assert 0 < active.sum() < active.size  # both words, the pause between them not
    assert np.allclose(np.linalg.norm(rows[active], axis=1), 1.0, atol=1e-5)
    assert not rows[~active].any()
    assert index.span(index.n_frames * HOP_S - 0.05, index.n_frames * HOP_S + 1.0).shape[0] \
        == 5  # clipped at the recording's end


def test_the_posteriorgram_index_has_the_same_frames(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "one.wav", [("capture", "rms/capture_1")], snr_db=10.0)
    mfcc = SpeechIndex.build(scene.samples, 16000)
    gram = SpeechIndex.build(scene.samples, 16000, representation="posteriorgram")
    np.testing.assert_array_equal(gram.frames, mfcc.frames)
    assert gram.n_frames == mfcc.n_frames and gram.seq.shape[0] == mfcc.seq.shape[0]
    assert np.allclose(np.linalg.norm(gram.seq, axis=1), 1.0, atol=1e-5)
