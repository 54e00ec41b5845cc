"""One camera recorded twice (raw and compressed): said on every opening and export of
its session, and left out of the session made without losing its review work."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from speechcal_core.export import export_session_file
from speechcal_core.pipeline import process_recording
from speechcal_core.review.loading import load_for_review
from speechcal_core.session.store import load_session, save_session
from speechcal_core.sources import StreamChoice

TWIN = "/cam0/image_raw/compressed"


def _with_a_twin(bag: Path, out: Path) -> None:
    """``bag`` with /cam0/image_raw recorded a second time as TWIN (same stamps)."""
    from rosbags.rosbag1 import Reader, Writer
    from rosbags.typesys import Stores, get_typestore

    types = get_typestore(Stores.ROS1_NOETIC)
    with Reader(bag) as reader, Writer(out) as writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=types)
                 for c in reader.connections}
        cam0 = next(c for c in reader.connections if c.topic == "/cam0/image_raw")
        twin = writer.add_connection(TWIN, cam0.msgtype, typestore=types)
        for conn, t, raw in reader.messages():
            writer.write(conns[conn.id], t, raw)
            if conn.topic == "/cam0/image_raw":
                writer.write(twin, t, raw)


@pytest.fixture
def twin_session(tiny_synth: tuple[Path, dict], tmp_path: Path) -> Path:
    folder, truth = tiny_synth
    bag = tmp_path / "twin.bag"
    _with_a_twin(folder / truth["recording"], bag)
    audio = tmp_path / "audio.ogg"
    shutil.copyfile(folder / truth["audio"], audio)
    words = tmp_path / "words.csv"
    words.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    session = process_recording([str(bag)], str(audio), transcript=str(words),
                                offset_ns=truth["sync"]["offset_ns"])
    path = tmp_path / "twin.json"
    save_session(session, path)
    return path


def test_a_twin_is_said_on_opening_and_on_export_until_it_is_left_out(
        twin_session: Path, tmp_path: Path) -> None:
    session = load_session(twin_session)
    session.replace_set(session.sets[0].with_decision("accepted"))
    save_session(session, twin_session)
    said = f"{TWIN} has the same header stamps as /cam0/image_raw, frame for frame"
    opened = load_for_review(session_path=twin_session)
    opened.close()
    assert said in opened.note
    exported = export_session_file(twin_session, "folders", tmp_path / "with_twin")
    assert any(said in note for note in exported.notes)

    narrowed = load_for_review(session_path=twin_session, streams=StreamChoice(skip=(TWIN,)))
    narrowed.close()
    assert f"left out {TWIN} (its frames, calibration and coverage" in narrowed.note
    assert said not in narrowed.note
    assert TWIN not in [s.name for s in narrowed.source.streams]
    kept = load_session(twin_session)
    assert kept.sets[0].decision == "accepted"  # the review work stays
    assert TWIN not in {f.stream for s in kept.sets for f in s.frames}
    exported = export_session_file(twin_session, "folders", tmp_path / "without_twin")
    assert not any(said in note for note in exported.notes)
    assert len([p for p in (tmp_path / "without_twin").iterdir() if p.is_dir()]) == 3
