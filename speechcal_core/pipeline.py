"""The processing facade the CLI and the GUI share: recording + audio -> a session.

Steps: index the recording, load the audio, find the clap (or take a known offset), find
the trigger words, choose every camera's best still frame for each trigger, find the target's
corners, and check a calibration per camera.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.session.model import Session, Trigger
from speechcal_core.sync.model import SyncModel

if TYPE_CHECKING:
    from speechcal_core.frames.detect import Target
    from speechcal_core.frames.sets import FrameSetOptions

Progress = Callable[[str, float], None]


def _noop(_text: str, _fraction: float) -> None:
    pass


def detect_trigger_words(audio, trigger_words: Sequence[str]) -> list[Trigger]:
    """Trigger words in ``audio`` (an :class:`~speechcal_core.audio.Audio`) as triggers."""
    from speechcal_core.speech.matching import TriggerSpec, match_triggers
    from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend

    spec = TriggerSpec(words=tuple(trigger_words))
    words = match_triggers(PocketsphinxBackend().words(audio, spec), spec)
    return [Trigger(w.word, w.start_s, w.end_s, w.score, w.source or "pocketsphinx")
            for w in words]


def process_recording(
    recording: Sequence[str],
    audio: str,
    *,
    trigger_words: Sequence[str] = ("capture",),
    transcript: str | None = None,
    offset_ns: int | None = None,
    target: Target | None = None,
    frame_options: FrameSetOptions | None = None,
    progress: Progress | None = None,
) -> Session:
    """Sync, detect and build frame sets; returns a new, undecided session.

    ``target`` defaults to Kalibr's 6x6 AprilGrid; ``frame_options`` sets the search window
    (or turns the best-still-frame search off).
    """
    from speechcal_core.audio import load_audio
    from speechcal_core.errors import NotYetAvailableError
    from speechcal_core.frames.analysis import analyse_frames
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.pipeline import sync_recording
    from speechcal_core.target import TargetSpec

    if transcript is not None:
        raise NotYetAvailableError("--transcript needs the speech layer's transcript import, "
                                   "which this version does not have yet")
    report = progress or _noop
    report("indexing the recording", 0.02)
    with open_recording(list(recording)) as source:
        report("reading the audio", 0.1)
        sound = load_audio(audio)
        evidence: dict = {}
        if offset_ns is not None:
            sync = SyncModel(int(offset_ns), 0.0, "manual")
        else:
            report("finding the clap", 0.2)
            result = sync_recording(source, sound,
                                    progress=lambda text: report(f"clap: {text}", 0.3))
            sync = result.model
            evidence = {k: v for k, v in result.to_dict().items()
                        if k not in ("offset_ns", "drift", "source")}
        report("finding the trigger words", 0.45)
        triggers = detect_trigger_words(sound.resampled(16000) if sound.rate != 16000
                                        else sound, trigger_words)

        def frames_progress(stage: str, fraction: float) -> None:
            start, span = {"windows": (0.6, 0.2), "corners": (0.8, 0.1)}.get(stage, (0.9, 0.1))
            report(f"frames: {stage}", start + span * fraction)

        report("choosing frames", 0.6)
        analysis = analyse_frames(source, sync, triggers, target or TargetSpec(),
                                  options=frame_options, progress=frames_progress)
        sets = analysis.sets
    session = Session(
        recording=[str(Path(p).absolute()) for p in recording],
        audio=str(Path(audio).absolute()),
        sync=sync,
        sets=sets,
        triggers_word=list(trigger_words),
        sync_evidence=evidence,
        calibration=analysis.calibration,
        extra=analysis.extra,
    )
    report("done", 1.0)
    return session
