"""Find more like this from one marked word (the review's S)."""

from __future__ import annotations

from pathlib import Path

from speech_scenes import make_scene, run_together

from speechcal_core.speech.more_like import find_more_like
from speechcal_core.speech.speech_index import SpeechIndex


def test_a_match_at_the_start_of_longer_speech_is_not_offered(tmp_path: Path) -> None:
    # "capture" said straight into "higher" matches the marked word at its start, but the
    # sound runs on without a pause, as in "captured it?"; the same take said alone is found
    items = [("capture", "rms/capture_1"), ("okay", "rms/okay_1"),
             ("capture higher", run_together("rms/capture_2", "rms/higher_1")),
             ("hold on", "rms/hold_on_1"), ("capture", "rms/capture_2")]
    scene = make_scene(tmp_path / "run_on.wav", items, snr_db=12.0, seed=1)
    index = SpeechIndex.build(scene.samples, 16000)
    mark = scene.spans("capture")[0]
    hits = find_more_like(index, *mark, "capture")
    alone = scene.spans("capture")[1]
    assert [round(w.t - (alone[0] + alone[1]) / 2, 1) for w in hits] == [0.0]
