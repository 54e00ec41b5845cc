"""Session files: round trip, relative paths, .bak, schema checks, clear errors."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
from speechcal_core.session.store import (
    SCHEMA,
    SessionChangedError,
    SessionFileError,
    SessionWriter,
    check_session_target,
    file_stamp,
    load_session,
    save_document,
    save_session,
    session_snapshot,
    session_text,
    session_to_dict,
)
from speechcal_core.sync.model import SyncModel


def _session(tmp_path: Path) -> Session:
    trig = Trigger("capture", 3.20, 3.62, 0.9)
    frames = (FrameChoice("/cam0/image_raw", 12, 1_000_400_000, 0.8, 144),
              FrameChoice("/cam1/image_raw", 6, 1_000_410_000, 0.7, 140))
    return Session(
        recording=[str(tmp_path / "data" / "rec.bag")],
        audio=str(tmp_path / "data" / "audio.ogg"),
        sync=SyncModel(1_000_000_000, 5e-6, "auto"),
        sets=[FrameSet(1, 1_000_405_000, trig, frames)],
    )


def test_round_trip_keeps_sets_and_decisions(tmp_path: Path) -> None:
    session = _session(tmp_path)
    session.replace_set(session.sets[0].with_decision("accepted"))
    path = tmp_path / "review" / "session.json"
    path.parent.mkdir()
    save_session(session, path)
    loaded = load_session(path)
    assert loaded.sets == session.sets
    assert loaded.sync == session.sync
    assert Path(loaded.recording[0]).resolve() == Path(session.recording[0]).resolve()



def test_a_decision_changes_one_line_of_the_file(tmp_path: Path) -> None:
    """A line per frame set (and per set's details): the file reads and diffs by set,
    and is written by json's fast encoder (indented output took 300 ms per autosave of a
    66-set session, on the window's thread)."""
    from dataclasses import replace

    session = _session(tmp_path)
    second = replace(session.sets[0], id=2, t_ns=2_000_000_000)
    session.sets.append(second)
    session.extra["frame_details"] = {"1": {"frames": {}}, "2": {"frames": {}}}
    path = tmp_path / "session.json"
    save_session(session, path)
    before = path.read_text().splitlines()
    assert before[1] == ' "schema": 1,'
    assert [line for line in before if '"t_ns"' in line] == [
        line for line in before if line.startswith('  {"id": ')]  # one line per set
    session.replace_set(second.with_decision("rejected"))
    save_session(session, path)
    after = path.read_text().splitlines()
    changed = [(a, b) for a, b in zip(before, after, strict=True) if a != b]
    assert len(changed) == 1 and '"decision": "rejected"' in changed[0][1]
    assert load_session(path).sets == session.sets


def test_an_autosave_writer_reencodes_only_what_was_replaced(tmp_path: Path) -> None:
    """The window keeps one SessionWriter: a set's details (the bulk of the file) that are
    the same object as at the last save keep their text; replaced ones are written anew."""
    session = _session(tmp_path)
    kept = {"frames": {"/cam0/image_raw": {"points": [[1.5, 2.5]], "ids": [0]}}}
    session.extra["frame_details"] = {"1": {"frames": {}}, "7": kept}
    path = tmp_path / "session.json"
    writer = SessionWriter()
    save_session(session, path, writer)
    session.replace_set(session.sets[0].with_decision("accepted"))
    session.extra["frame_details"]["1"] = {"frames": {}, "score": 0.5}  # replaced
    save_session(session, path, writer)
    # the same text as a writer with no memory, and it reads back
    assert path.read_text() == session_text(session_to_dict(session, path))
    assert json.loads(path.read_text())["frame_details"] == {
        "1": {"frames": {}, "score": 0.5}, "7": kept}
    assert load_session(path).sets == session.sets
    # unchanged details are not encoded again: the review model replaces a set's details,
    # never edits them in place, and a change made in place would not reach the file
    kept["frames"]["/cam0/image_raw"]["ids"] = [9]
    save_session(session, path, writer)
    assert '"ids": [0]' in path.read_text()
    assert '"ids": [9]' in session_text(session_to_dict(session, path))  # no memory


def test_a_snapshot_writes_the_session_as_it_was_when_taken(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An autosave's snapshot (written later, on a worker thread) gives the text the
    session had when it was taken, whatever the review changes meanwhile; a writer kept
    from save to save encodes a set that did not change only once."""
    session = _session(tmp_path)
    first = session.sets[0]
    session.sets.append(FrameSet(2, first.t_ns + 10**9, first.trigger, first.frames))
    session.extra["frame_details"] = {"1": {"frames": {}}}
    path = tmp_path / "session.json"
    expected = session_text(session_to_dict(session, path))
    snapshot = session_snapshot(session, path)
    session.replace_set(session.sets[0].with_decision("rejected"))  # after the snapshot
    session.extra["frame_details"]["2"] = {"frames": {}}
    del session.extra["frame_details"]["1"]
    session.calibration["/cam9"] = {"rms_px": 1.0}
    writer = SessionWriter()
    save_document(snapshot, path, writer)
    assert path.read_text() == expected
    assert load_session(path).sets[0].decision == "undecided"
    save_document(session_snapshot(session, path), path, writer)
    assert path.read_text() == session_text(session_to_dict(session, path))
    assert load_session(path).sets == session.sets
    import speechcal_core.session.store as store

    encoded: list[object] = []
    real = store._dumps
    monkeypatch.setattr(store, "_dumps", lambda value: encoded.append(value) or real(value))
    session.replace_set(session.sets[1].with_decision("accepted"))
    save_document(session_snapshot(session, path), path, writer)
    set_lines = [v for v in encoded if isinstance(v, dict) and "decision" in v]
    assert [v["id"] for v in set_lines] == [session.sets[1].id]  # only the set changed
    assert load_session(path).sets == session.sets


def test_details_an_undo_brings_back_are_not_encoded_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An offset edit replaces every set's details and its undo brings the old objects
    back: the writer still has their text (megabytes with a dozen cameras), so the save
    after the undo encodes nothing of them; the file is as a writer without memory
    writes it. Lines kept that long are let go after KEEP_SAVES saves."""
    import speechcal_core.session.store as store

    session = _session(tmp_path)
    before = {"frames": {"/cam0/image_raw": {"points": [[1.5, 2.5]], "ids": [0]}}}
    session.extra["frame_details"] = {"1": before}
    path = tmp_path / "session.json"
    writer = SessionWriter()
    save_document(session_snapshot(session, path), path, writer)
    session.extra["frame_details"] = {}  # the offset edit drops them
    save_document(session_snapshot(session, path), path, writer)
    session.extra["frame_details"] = {"1": before}  # its undo brings them back
    encoded: list[object] = []
    real = store._dumps
    monkeypatch.setattr(store, "_dumps", lambda value: encoded.append(value) or real(value))
    save_document(session_snapshot(session, path), path, writer)
    assert before not in encoded
    assert path.read_text() == session_text(session_to_dict(session, path))
    session.extra["frame_details"] = {}
    for _ in range(SessionWriter.KEEP_SAVES + 1):
        save_document(session_snapshot(session, path), path, writer)
    session.extra["frame_details"] = {"1": before}
    save_document(session_snapshot(session, path), path, writer)
    assert before in encoded  # long gone: encoded again


def test_a_file_changed_since_it_was_read_is_not_overwritten(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    session = _session(tmp_path)
    save_session(session, path)
    read_at = file_stamp(path)
    other = load_session(path)  # another window decides and saves
    other.replace_set(other.sets[0].with_decision("rejected"))
    save_session(other, path)
    session.replace_set(session.sets[0].with_decision("accepted"))
    with pytest.raises(SessionChangedError, match="another window or program saved it"):
        save_session(session, path, expect=read_at)
    assert load_session(path).sets[0].decision == "rejected"
    save_session(session, path, expect=file_stamp(path))  # read again: saved
    assert load_session(path).sets[0].decision == "accepted"
    assert file_stamp(tmp_path / "missing.json") is None


def test_the_audio_channel_is_kept_and_a_bad_one_is_named(tmp_path: Path) -> None:
    session = _session(tmp_path)
    path = tmp_path / "session.json"
    save_session(session, path)
    assert "audio_channel" not in json.loads(path.read_text())  # mixed: nothing stored
    session.audio_channel = 1
    save_session(session, path)
    assert load_session(path).audio_channel == 1
    doc = json.loads(path.read_text())
    doc["audio_channel"] = "left"
    path.write_text(json.dumps(doc))
    with pytest.raises(SessionFileError, match="'audio_channel' is 'left', not a channel "
                                               "number from 0"):
        load_session(path)

def test_the_streams_used_are_kept_and_bad_ones_are_named(tmp_path: Path) -> None:
    from dataclasses import replace

    from speechcal_core.sources import StreamChoice

    session = _session(tmp_path)
    path = tmp_path / "session.json"
    save_session(session, path)
    assert load_session(path).stream_choice() is None  # all streams
    session.extra["streams"] = ["/cam0/image_raw"]
    session.sets = [replace(s, frames=s.frames[:1]) for s in session.sets]  # cam0's only
    save_session(session, path)
    assert load_session(path).stream_choice() == StreamChoice(only=("/cam0/image_raw",))
    for bad in ("/cam0/image_raw", [], [3]):
        doc = json.loads(path.read_text())
        doc["streams"] = bad
        path.write_text(json.dumps(doc))
        with pytest.raises(SessionFileError, match=r"'streams' is .*, not a list of stream "
                                                   r"names"):
            load_session(path)


def test_file_starts_with_schema_and_stores_relative_paths(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    text = path.read_text()
    assert text.lstrip("{\n ").startswith('"schema"')
    data = json.loads(text)
    assert data["schema"] == SCHEMA
    assert data["recording"] == ["data/rec.bag"]
    assert data["audio"] == "data/audio.ogg"
    assert data["sets"][0]["frames"][0]["corners"] == 144
    assert set(data["sync"]) >= {"offset_ns", "drift"}


def test_the_sync_audio_path_is_relative_to_the_session_file_too(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    session = _session(tmp_path)
    monkeypatch.chdir(tmp_path / "..")  # the sync ran with a path relative to elsewhere
    given = str(Path(tmp_path.name) / "data" / "audio.ogg")
    session.sync_evidence = {"audio": {"path": given, "rate": 48000}, "claps": []}
    path = tmp_path / "review" / "session.json"
    path.parent.mkdir()
    save_session(session, path)
    stored = json.loads(path.read_text())["sync"]["audio"]
    assert stored == {"path": "../data/audio.ogg", "rate": 48000}
    loaded = load_session(path).sync_evidence["audio"]["path"]
    assert Path(loaded).resolve() == (tmp_path / "data" / "audio.ogg").resolve()


def test_a_missing_folder_is_named_when_saving(tmp_path: Path) -> None:
    path = tmp_path / "gone" / "session.json"
    for attempt in (lambda: save_session(_session(tmp_path), path),
                    lambda: check_session_target(path)):
        with pytest.raises(SessionFileError, match=f"the folder {path.parent} does not exist"):
            attempt()
    (tmp_path / "file").write_text("x")
    with pytest.raises(SessionFileError, match="is a file, not a folder"):
        save_session(_session(tmp_path), tmp_path / "file" / "session.json")
    (tmp_path / "file").unlink()
    check_session_target(tmp_path / "session.json")  # a writable folder passes
    assert list(tmp_path.iterdir()) == []  # and the check leaves nothing behind


def test_second_save_keeps_previous_version_as_bak(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    session = _session(tmp_path)
    save_session(session, path)
    session.replace_set(session.sets[0].with_decision("rejected"))
    save_session(session, path)
    assert json.loads(path.with_name("session.json.bak").read_text())["sets"][0][
        "decision"] == "undecided"
    assert load_session(path).sets[0].decision == "rejected"


def test_a_session_reached_through_a_link_is_saved_in_its_target(tmp_path: Path) -> None:
    """The link stays a link: the target holds the saved work, its .bak and the atomic
    replace's temp file lie beside the target, and the stored paths stay relative to the
    target's folder (the link's folder has no data/ beside it)."""
    session = _session(tmp_path)
    target = tmp_path / "session.json"
    save_session(session, target)
    elsewhere = tmp_path / "links"
    elsewhere.mkdir()
    link = elsewhere / "my-review.json"
    link.symlink_to(os.path.relpath(target, elsewhere))
    loaded = load_session(link)
    assert loaded.recording == [str(tmp_path / "data" / "rec.bag")]  # not links/data/
    stamp = file_stamp(link)
    loaded.replace_set(loaded.sets[0].with_decision("accepted"))
    save_session(loaded, link, expect=stamp)
    assert link.is_symlink() and link.resolve() == target
    data = json.loads(target.read_text())
    assert data["sets"][0]["decision"] == "accepted"
    assert data["recording"] == ["data/rec.bag"]
    assert json.loads((tmp_path / "session.json.bak").read_text())["sets"][0][
        "decision"] == "undecided"
    assert sorted(p.name for p in elsewhere.iterdir()) == ["my-review.json"]
    assert load_session(link).sets[0].decision == "accepted"


def test_newer_schema_is_refused_with_update_hint(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    data = json.loads(path.read_text())
    data["schema"] = SCHEMA + 1
    path.write_text(json.dumps(data))
    with pytest.raises(SessionFileError, match=r"newer SpeechCal.*update"):
        load_session(path)


def _edited(tmp_path: Path, edit) -> Path:
    """A saved session file after ``edit`` (a function on its JSON document)."""
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(("edit", "says"), [
    (lambda d: d.update(schema="1"), "'schema' is '1', not a schema number from 1 to"),
    (lambda d: d["sync"].update(drift=float("nan")), "the sync's drift is nan"),
    (lambda d: d["sync"].update(offset_ns=float("inf")), "cannot convert float infinity"),
    # every session time computed from these overflowed: export and the window raised
    (lambda d: d["sync"].update(offset_ns=10**25),
     "the sync's offset_ns 10000000000000000000000000 is no camera-clock time"),
    (lambda d: d["sync"].update(offset_ns=2**63 - 1),
     "the sync's offset_ns 9223372036854775807 is no camera-clock time"),
    (lambda d: d["sets"].append(dict(d["sets"][0])), "set id 1 appears twice"),
    # a session without its list of sets opened as one with no sets, and the next save
    # wrote that over the file
    (lambda d: d.pop("sets"), "the key 'sets' is missing"),
    (lambda d: d.update(sets={}), "'sets' is {}, not a list of frame sets"),
    (lambda d: d.update(sets=None), "'sets' is None, not a list of frame sets"),
    (lambda d: d.update(last_set_id="7"), "'last_set_id' is '7', not a set number"),
    # export and the window said the recording lacked the camera: another recording's
    (lambda d: d.update(streams=["/cam0/image_raw"]),
     "set 1 shows /cam1/image_raw, which 'streams' leaves out; put it back in the list, "
     "and leave a camera out with speechcal review SESSION.json --skip-stream "
     "/cam1/image_raw (its frames go too)"),
    # the review window joins them as text (the words named when others are asked for)
    (lambda d: d.update(trigger_words=[1]), "'trigger_words' is [1], not a list of words"),
    (lambda d: d["sets"][0].update(decision="yes"),
     "set 1: decision 'yes' is none of accepted, rejected, undecided"),
    (lambda d: d["sets"][0].pop("trigger"), "set 1: the key 'trigger' is missing"),
    # the session times computed from these overflowed, and the review window raised
    (lambda d: d["sets"][0]["trigger"].update(start_s=float("nan")),
     "set 1: its trigger's start_s nan is no time in the audio (seconds)"),
    (lambda d: d["sets"][0]["trigger"].update(end_s=1e12),
     "set 1: its trigger's end_s 1000000000000.0 is no time in the audio (seconds)"),
    (lambda d: d["sets"][0].pop("id"), "set number 1 in the list: the key 'id' is missing"),
    (lambda d: d["sets"][0].update(frames=None), "set 1: a value of the wrong kind"),
    # the window compared such figures with numbers and raised
    (lambda d: d["sets"][0]["frames"][0].update(sharpness="0.8 "),
     "set 1: /cam0/image_raw's sharpness is '0.8 ', not a number"),
    (lambda d: d["sets"][0]["frames"][1].update(corners=[140]),
     "set 1: /cam1/image_raw's corners is [140], not a number"),
    (lambda d: d["sets"][0]["frames"][1].update(flags="blurred"),
     "set 1: /cam1/image_raw's flags is 'blurred', not a list of flags"),
    (lambda d: d["sets"][0]["frames"][0].update(index=10**12),
     "set 1: /cam0/image_raw's frame index is 1000000000000, beyond any recording"),
    # session time is int64 nanoseconds: 1.5e300 read as a whole number became a 300-digit
    # file name, which export failed to write ("File name too long; check free disk space")
    (lambda d: d["sets"][0].update(t_ns=1.5e300),
     "set 1: its time t_ns 1.5e+300 is no camera-clock time in nanoseconds"),
    (lambda d: d["sets"][0]["frames"][0].update(stamp_ns=-(2**70)),
     "set 1: /cam0/image_raw's stamp_ns -1180591620717411303424 is no camera-clock time"),
    # the window's calibration line formatted these as numbers and raised
    (lambda d: d.update(coverage="full"), "'coverage' is 'full', not the cameras' coverage"),
    (lambda d: d.update(coverage={"/cam0/image_raw": 5}),
     "the coverage of /cam0/image_raw is 5, not its views and progress"),
    (lambda d: d.update(coverage={"/cam0/image_raw": {"views": "4"}}),
     "the coverage of /cam0/image_raw: its views is '4', not a count"),
    (lambda d: d.update(coverage={"/cam0/image_raw": {"views": 4, "progress": [0.3]}}),
     "the coverage of /cam0/image_raw: its progress is [0.3], not x, y, size and skew"),
    (lambda d: d.update(coverage={"/cam0/image_raw": {"views": 4, "progress": {"x": "30%"}}}),
     "the coverage of /cam0/image_raw: its progress x is '30%', not a number; deleting the "
     "'coverage' key is a fix too"),
    (lambda d: d.update(calibration="good"),
     "'calibration' is 'good', not the cameras' fitted models"),
    (lambda d: d.update(calibration={"/cam0/image_raw": {"model": "pinhole", "rms_px": "0.1"}}),
     "the calibration of /cam0/image_raw: its rms_px is '0.1', not a number; deleting the "
     "'calibration' key is a fix too"),
    (lambda d: d.update(calibration={"/cam0/image_raw": {"rms_px": 0.1, "views": 12}}),
     "the calibration of /cam0/image_raw: its views is 12, not a list"),
])
def test_a_hand_edit_gone_wrong_names_the_set_and_what_is_wrong(tmp_path: Path, edit,
                                                                 says: str) -> None:
    path = _edited(tmp_path, edit)
    with pytest.raises(SessionFileError) as exc:
        load_session(path)
    assert str(exc.value).startswith(f"{path}: damaged session file")
    assert says in str(exc.value) and "\n" not in str(exc.value)
    assert ".bak" not in str(exc.value)  # saved once: there is no earlier version to offer


def test_coverage_as_the_check_writes_it_or_without_it_opens(tmp_path: Path) -> None:
    """A camera without views (progress and ranges null), and no coverage at all (the
    fix a damaged one's message offers), both read."""
    cover = {"/cam0/image_raw": {"views": 3, "progress": {"x": 0.31, "y": 1}, "ranges": {}},
             "/cam1/image_raw": {"views": 0, "progress": None, "ranges": None}}
    assert load_session(_edited(tmp_path, lambda d: d.update(coverage=cover))
                        ).extra["coverage"] == cover
    assert "coverage" not in load_session(_edited(tmp_path, lambda d: d.pop("coverage", 0))
                                          ).extra


@pytest.mark.parametrize(("damage", "says"), [
    (lambda p: p.write_text(p.read_text()[:40]),
     "not valid JSON (line 4), the file is damaged; restore it from a copy, or process the "
     "recording again (speechcal process)"),
    (lambda p: p.write_text("[" * 100_000 + "]" * 100_000),
     "not a session file (its JSON nests too deeply)"),
    (lambda p: p.write_text("target_type: checkerboard\n"),  # -o given a target's name
     "not a session file (not JSON); a session file is what 'speechcal process' writes"),
    (lambda p: (p.unlink(), p.mkdir()), "a folder, not a session file; give the session's "
                                         ".json file"),
])
def test_a_file_that_is_no_session_says_what_it_is_and_what_to_do(tmp_path: Path, damage,
                                                                 says: str) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    damage(path)
    with pytest.raises(SessionFileError) as exc:
        load_session(path)
    assert str(exc.value) == f"{path}: {says}"


def test_a_damaged_set_offers_the_earlier_version_when_there_is_one(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    _edited(tmp_path, lambda d: d["sets"][0].update(decision="yes"))  # saved again: a .bak
    with pytest.raises(SessionFileError, match=r"set 1: .*fix it or go back to session\.json\.bak"):
        load_session(path)


def test_decisions_written_by_hand_in_capitals_are_read(tmp_path: Path) -> None:
    path = _edited(tmp_path, lambda d: d["sets"][0].update(decision="Accepted"))
    assert load_session(path).sets[0].decision == "accepted"


def test_one_trigger_word_written_by_hand_is_that_word(tmp_path: Path) -> None:
    """Read as a list, "snapshot" was eight one-letter words: a set added in the review
    window took "s" for its word."""
    path = _edited(tmp_path, lambda d: d.update(trigger_words=" snapshot"))
    assert load_session(path).triggers_word == ["snapshot"]


def test_a_byte_order_mark_from_an_editor_is_read(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert load_session(path).sets == _session(tmp_path).sets


def test_a_recording_given_as_the_session_says_how_to_open_it(tmp_path: Path) -> None:
    path = tmp_path / "rec.bag"
    path.write_bytes(b"#ROSBAG V2.0\n\x00\xff\xfe" + bytes(range(256)))
    with pytest.raises(SessionFileError, match=r"not a session file .*--audio AUDIO"):
        load_session(path)


def test_broken_json_names_file_and_backup(tmp_path: Path) -> None:
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    save_session(_session(tmp_path), path)
    path.write_text('{"schema": 1, "sets": [')
    with pytest.raises(SessionFileError, match=r"not valid JSON.*session\.json\.bak"):
        load_session(path)


def test_missing_file_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(SessionFileError, match="no such session file; check the path"):
        load_session(tmp_path / "nope.json")


def test_a_missing_file_whose_backup_is_there_names_the_backup(tmp_path: Path) -> None:
    """Deleted (or renamed) by mistake: the previous version beside it is the way back."""
    path = tmp_path / "session.json"
    save_session(_session(tmp_path), path)
    save_session(_session(tmp_path), path)
    path.unlink()
    with pytest.raises(SessionFileError, match=r"no such session file; its previous version "
                                               r"is in session\.json\.bak: rename it"):
        load_session(path)


def test_a_synthetic_sessions_truth_file_is_refused_and_left_alone(
        tiny_synth: tuple[Path, dict]) -> None:
    folder, _truth = tiny_synth
    truth_file = folder / "truth.json"
    before = truth_file.read_bytes()
    with pytest.raises(SessionFileError) as err:
        load_session(truth_file)
    assert str(truth_file) in str(err.value)
    assert "truth file of a synthetic session" in str(err.value)
    assert "--audio" in str(err.value)
    assert truth_file.read_bytes() == before


@pytest.mark.parametrize("data", [
    {"schema": 1, "recording": 3, "sync": {}},
    {"schema": 1, "recording": [], "sync": {"offset_ns": 0}},
    {"schema": 1, "recording": ["rec.bag"], "sync": [1, 2]},
])
def test_json_with_a_schema_but_no_session_shape_is_not_a_session(tmp_path: Path,
                                                                   data: dict) -> None:
    path = tmp_path / "other.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(SessionFileError, match="not a SpeechCal session file"):
        load_session(path)


@pytest.mark.parametrize("code, advice", [
    (errno.EACCES, "choose a folder you can write to (or make this one writable)"),
    (errno.EROFS, "choose a folder you can write to"),
    (errno.ENOSPC, "free disk space or choose a folder on another disk"),
])
def test_a_session_that_cannot_be_saved_gets_advice_for_its_reason(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int, advice: str) -> None:
    """A read-only folder was told to "free disk space" (root, which these tests run as,
    writes anywhere: the system's reason is given here as it would come)."""
    import speechcal_core.session.store as store

    monkeypatch.setattr(store, "folder_write_problem", lambda _folder: os.strerror(code))
    with pytest.raises(SessionFileError) as err:
        check_session_target(tmp_path / "session.json")
    assert f"({os.strerror(code)}); {advice}" in str(err.value)
