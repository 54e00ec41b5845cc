"""Write a whole synthetic session: recording, audio.ogg and truth.json (``speechcal synth``)."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

from speechcal_core.fsutil import OutputExistsError, atomic_write_text, staged_directory
from speechcal_core.sources.index_cache import INDEX_SUFFIX
from speechcal_core.synth.audio import AudioTruth, render_audio
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.recording_writer import RecordingTruth, write_recording
from speechcal_core.synth.timeline import Timeline, plan_session
from speechcal_core.synth.voices import check_trigger_word
from speechcal_core.text import listed

#: the board the session shows, as a Kalibr target yaml (for `speechcal process --target`)
TARGET_FILE = "target.yaml"

TRUTH_SCHEMA = 1


def generate_session(
    out: str | Path,
    options: SynthOptions,
    *,
    force: bool = False,
    progress: Callable[[str, float], None] | None = None,
) -> dict:
    """Write recording, ``audio.ogg``, ``truth.json`` and the board's Kalibr
    ``target.yaml`` (for ``process --target``) into ``out``; return the truth.

    ``out`` appears complete or not at all; an existing ``out`` needs ``force``, and is
    replaced only when :func:`not_replaceable` says it may be.
    """
    check_trigger_word(options.trigger_word)  # fail before any rendering
    out = Path(out).absolute()
    problem = not_replaceable(out)
    if problem:  # not even --force replaces it
        raise OutputExistsError(f"{out}: {problem}; choose another folder")
    timeline = plan_session(options)
    with staged_directory(out, force=force, may_replace=not_replaceable) as staging:
        report = (lambda stage: (lambda f: progress(stage, f))) if progress else (lambda _s: None)
        recording = write_recording(timeline, staging, progress=report("video"))
        audio = render_audio(timeline, staging / "audio.ogg", progress=report("audio"))
        truth = build_truth(timeline, recording, audio, staging)
        atomic_write_text(staging / "truth.json", json.dumps(truth, indent=2) + "\n")
        atomic_write_text(staging / TARGET_FILE, timeline.target.to_kalibr_yaml())
    return truth


def not_replaceable(out: Path) -> str:
    """Why ``out`` must not be replaced by a new synthetic session even when forced ("" if
    it may): a file, or a folder holding anything but an earlier one (the files its
    truth.json names, and recording indexes). Review work saved beside a recording, or
    the user's own files, are never replaced."""
    if out.is_symlink() or not out.exists():
        return ""
    if not out.is_dir():
        return "this is a file, not a synthetic session's folder"
    names = sorted(child.name for child in out.iterdir())
    if not names:
        return ""
    try:
        truth = json.loads((out / "truth.json").read_text(encoding="utf-8"))
        own = {"truth.json", TARGET_FILE, str(truth["recording"]), str(truth["audio"])}
    except (OSError, UnicodeDecodeError, ValueError, TypeError, KeyError):
        return (f"this folder holds files that are not a synthetic session "
                f"({listed(names)}), and synth never replaces those")
    other = [n for n in names if n not in own and not n.endswith(INDEX_SUFFIX)]
    if other:
        return (f"this synthetic session's folder also holds files synth did not write "
                f"({listed(other)}: review work, notes?), and synth never replaces those")
    return ""



def build_truth(
    timeline: Timeline, recording: RecordingTruth, audio: AudioTruth, root: Path
) -> dict:
    """The truth.json document (DESIGN.md §2) with paths relative to ``root``."""
    sync = timeline.sync
    holds = timeline.holds
    triggers = []
    for trig in audio.triggers:
        mid = (trig["start_s"] + trig["end_s"]) / 2
        hold = holds[trig["hold"]]
        triggers.append({
            "word": trig["word"],
            "start_s": trig["start_s"],
            "end_s": trig["end_s"],
            "session_ns": sync.to_session(mid),
            "hold": [hold.start_ns, hold.end_ns],
            "voice": trig["voice"],  # who says it (tests of same-speaker searches)
            "clip": trig["clip"],
        })
    options = asdict(timeline.options)
    return {
        "schema": TRUTH_SCHEMA,
        "recording": recording.path.relative_to(root).as_posix(),
        "audio": "audio.ogg",
        "format": recording.format,
        "encoding": timeline.options.encoding,
        "seed": timeline.options.seed,
        "options": options,
        "start_ns": timeline.start_ns,
        "end_ns": timeline.end_ns,
        "sync": {"offset_ns": sync.offset_ns, "drift": sync.drift},
        "claps": [
            {"audio_s": a, "session_ns": c}
            for a, c in zip(audio.claps, timeline.claps_ns, strict=True)
        ],
        "triggers": triggers,
        "distractors": audio.distractors,
        "events": audio.events,
        "holds": [[h.start_ns, h.end_ns] for h in holds],
        "target": asdict(timeline.target),
        "cameras": [
            {**cam.truth_dict(), "count": len(recording.stamps[cam.name]),
             "dropped": int(recording.dropped.get(cam.name, 0))}
            for cam in timeline.cameras
        ],
        "audio_info": {"sample_rate": audio.sample_rate, "duration_s": audio.duration_s},
    }
