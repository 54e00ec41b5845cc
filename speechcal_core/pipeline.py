"""The processing facade the CLI and the GUI share: recording + audio -> a session.

Steps: index the recording, load the audio, find the clap (or take a known offset), find
the trigger words, and choose every camera's frame for each trigger.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from speechcal_core.session.model import Session, Trigger
from speechcal_core.sync.model import SyncModel

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
    offset_ns: int | None = None,
    progress: Progress | None = None,
) -> Session:
    """Sync, detect and build frame sets; returns a new, undecided session."""
    from speechcal_core.audio import load_audio
    from speechcal_core.frames.nearest import nearest_frame_sets
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.pipeline import sync_recording

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
        report("choosing frames", 0.85)
        sets = nearest_frame_sets(source, sync, triggers)
    session = Session(
        recording=[str(Path(p).absolute()) for p in recording],
        audio=str(Path(audio).absolute()),
        sync=sync,
        sets=sets,
        triggers_word=list(trigger_words),
        sync_evidence=evidence,
    )
    report("done", 1.0)
    return session
