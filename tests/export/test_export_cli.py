"""``speechcal export``: exit codes, one-line errors, --json, --force, nothing left behind."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from speechcal_core.cli import main
from speechcal_core.export import export_session_file
from speechcal_core.export.notes import approx_sync_note
from speechcal_core.session.store import load_session


def _run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(["export", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _leftovers(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


def test_json_prints_one_document_on_stdout_and_progress_on_stderr(session_file, tmp_path):
    path = session_file()
    out = tmp_path / "exp"
    result = subprocess.run(
        [sys.executable, "-m", "speechcal_core.cli", "export", str(path), "--format",
         "rosbag2", "--out", str(out), "--json"],
        capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stderr
    doc = json.loads(result.stdout)
    # the bag keeps each frame's stamp: frames of a set lie 41.4 ms apart here, further
    # than Kalibr's default pairing
    accepted = [s for s in load_session(path).sets if s.decision == "accepted"]
    assert max(s.skew_ns for s in accepted) > 40_000_000
    assert doc == {"out": str(out), "format": "rosbag2", "sets": 3, "frames": 6,
                   "files": doc["files"], "skipped": [], "notes": doc["notes"],
                   "target": "default"}
    board_note, sync_note = doc["notes"]
    assert sync_note == approx_sync_note(accepted) and "--approx-sync 0.05 " in sync_note
    assert board_note.startswith("target.yaml describes the 6x6 AprilGrid")
    # metadata.yaml, calibration.db3, target.yaml (for --target), manifest.json and .csv
    assert doc["files"] == 5
    assert "writing the manifest" in result.stderr


def test_existing_folder_is_refused_naming_it_and_force(session_file, tmp_path, capsys) -> None:
    path = session_file()
    out = tmp_path / "exp"
    out.mkdir()  # empty: --force may replace it
    code, stdout, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(out))
    assert code == 1 and stdout == ""
    assert err.count("\n") == 1 and str(out) in err and "--force" in err
    (out / "keep.txt").write_text("mine")  # not even --force replaces it: not offered
    code, stdout, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(out))
    assert code == 1 and stdout == "" and "--force" not in err
    assert "holds files that are not an export (keep.txt)" in err
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_force_replaces_an_earlier_export_and_leaves_no_temporary_folders(
    session_file, tmp_path, capsys
) -> None:
    path = session_file()
    out = tmp_path / "exp"
    code, _stdout, _err = _run(capsys, str(path), "--format", "kalibr", "--out", str(out))
    assert code == 0 and (out / "cam0").is_dir()
    code, stdout, _err = _run(capsys, str(path), "--format", "folders", "--out", str(out),
                              "--force")
    assert code == 0 and "exported 3 frame sets" in stdout
    assert not (out / "cam0").exists() and (out / "manifest.json").exists()
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("extra", ["calibration-camchain.yaml", "cam0/notes.txt"])
def test_force_never_replaces_an_earlier_export_holding_other_files(
        session_file, tmp_path, capsys, extra: str) -> None:
    """Kalibr's results, or notes, put into an earlier export are the operator's work."""
    path = session_file()
    out = tmp_path / "exp"
    assert _run(capsys, str(path), "--format", "kalibr", "--out", str(out))[0] == 0
    (out / extra).write_text("results")
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    code, _stdout, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(out),
                              "--force")
    assert code == 1 and f"also holds files it did not write ({extra})" in err
    assert "an export never replaces those; choose another output folder" in err
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before


@pytest.mark.parametrize("fmt", ["kalibr", "rosbag1"])
def test_force_keeps_an_earlier_export_whose_target_yaml_was_measured_and_edited(
        session_file, tmp_path, capsys, fmt: str) -> None:
    """A tag size put right by hand in an exported target.yaml was written over by the
    next --force without a word; the edited board is now kept, or taken with --target."""
    path = session_file()
    out = tmp_path / "exp"
    assert _run(capsys, str(path), "--format", fmt, "--out", str(out))[0] == 0
    target = out / "target.yaml"
    edited = target.read_text().replace("tagSize: 0.055", "tagSize: 0.0588")
    assert edited != target.read_text()
    target.write_text(edited)
    code, stdout, err = _run(capsys, str(path), "--format", fmt, "--out", str(out),
                             "--force")
    assert code == 1 and stdout == "" and err.count("\n") == 1
    assert ("its target.yaml was changed after the export wrote it: it describes a 6x6 "
            "AprilGrid of 0.0588 m tags, the export wrote a 6x6 AprilGrid of 0.055 m tags")\
        in err
    assert f"give {target} as the target (speechcal export --target" in err
    assert target.read_text() == edited

    # the edited file itself is the target: it is read before the folder is replaced
    code, _stdout, _err = _run(capsys, str(path), "--format", "kalibr", "--out", str(out),
                               "--force", "--target", str(target))
    assert code == 0, _err
    assert "tagSize: 0.0588" in target.read_text()
    # that export wrote the measured board: the next --force may replace it again
    measured = tmp_path / "measured.yaml"
    measured.write_text(edited)
    assert _run(capsys, str(path), "--format", "kalibr", "--out", str(out), "--force",
                "--target", str(measured))[0] == 0


def test_an_export_inside_an_earlier_export_is_refused(session_file, tmp_path, capsys) -> None:
    """Kalibr reads a camera folder with everything under it: frames exported into an
    earlier export would join its calibration, and that export could not be replaced."""
    path = session_file()
    out = tmp_path / "exp"
    assert _run(capsys, str(path), "--format", "kalibr", "--out", str(out))[0] == 0
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    nested = out / "cam0" / "nested"
    code, stdout, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(nested))
    assert code == 1 and stdout == "" and err.count("\n") == 1
    assert f"{nested}: this lies inside the earlier export {out}" in err
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before
    assert _run(capsys, str(path), "--format", "kalibr", "--out", str(out), "--force")[0] == 0


def test_force_replaces_an_empty_folder(session_file, tmp_path, capsys) -> None:
    out = tmp_path / "exp"
    out.mkdir()
    code, _stdout, _err = _run(capsys, str(session_file()), "--format", "folders", "--out",
                              str(out), "--force")
    assert code == 0 and (out / "manifest.json").exists()


def test_an_empty_out_is_bad_usage_not_the_current_folder(session_file, tmp_path,
                                                          monkeypatch, capsys) -> None:
    """``--out ""`` (an unset shell variable) meant the current folder: with --force an
    empty one was replaced by the export."""
    path = session_file()
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    with pytest.raises(SystemExit) as exc:
        main(["export", str(path), "--format", "kalibr", "--out", "", "--force"])
    assert exc.value.code == 2
    assert "speechcal export: error: argument --out: an empty name; give the folder to " \
        "write the export to" in capsys.readouterr().err
    assert list(here.iterdir()) == []


def test_force_never_replaces_a_folder_of_other_files(session_file, tmp_path, capsys) -> None:
    """One slip (``--out ~/data --force``) must not delete someone's work."""
    out = tmp_path / "data"
    (out / "thesis").mkdir(parents=True)
    (out / "thesis" / "ch1.tex").write_text("mine")
    (out / "manifest.json").write_text('{"name": "some other tool"}')
    code, stdout, err = _run(capsys, str(session_file()), "--format", "kalibr", "--out",
                             str(out), "--force")
    assert code == 1 and stdout == "" and err.count("\n") == 1
    assert str(out) in err and "not an export (manifest.json, thesis)" in err
    assert "choose another output folder" in err
    assert (out / "thesis" / "ch1.tex").read_text() == "mine"
    assert _leftovers(tmp_path) == []


def test_cancelled_export_leaves_nothing_and_keeps_the_old_folder(session_file, tmp_path):
    path = session_file()

    class Stop(Exception):
        pass

    def stop_halfway(text: str, fraction: float) -> None:
        if fraction > 0.5:
            raise Stop(text)

    with pytest.raises(Stop):
        export_session_file(path, "kalibr", tmp_path / "new", progress=stop_halfway)
    assert not (tmp_path / "new").exists()
    old = tmp_path / "old"
    export_session_file(path, "folders", old)
    before = sorted(p.name for p in old.iterdir())
    with pytest.raises(Stop):
        export_session_file(path, "rosbag1", old, force=True, progress=stop_halfway)
    assert sorted(p.name for p in old.iterdir()) == before
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP"])
def test_a_killed_export_or_closed_terminal_leaves_nothing_as_ctrl_c_does(
        session_file, tmp_path, capsys, monkeypatch, name: str) -> None:
    from speechcal_core.export import run

    number = getattr(signal, name, None)
    if number is None:
        pytest.skip(f"no {name} here")
    before = signal.getsignal(number)
    write = run._write

    def write_then_signal(*args):
        written = write(*args)
        os.kill(os.getpid(), number)  # a real signal, mid-export
        return written

    monkeypatch.setattr(run, "_write", write_then_signal)
    out = tmp_path / "out"
    code, _stdout, err = _run(capsys, str(session_file()), "--format", "folders", "--out",
                              str(out))
    assert code == 128 + number
    assert err.splitlines()[-1] == f"speechcal export: stopped by {name}"
    assert not out.exists() and _leftovers(tmp_path) == []
    assert signal.getsignal(number) is before


@pytest.mark.parametrize("fmt", ["rosbag2", "folders"])
def test_a_full_disk_is_one_line_naming_the_output_and_leaves_nothing(session_file, tmp_path,
                                                                       fmt) -> None:
    import resource
    import signal

    def small_files() -> None:  # writes past 20 kB fail as on a full disk
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    path, out = session_file(), tmp_path / "exp"
    result = subprocess.run(
        [sys.executable, "-m", "speechcal_core.cli", "export", str(path), "--format", fmt,
         "--out", str(out)],
        capture_output=True, text=True, timeout=120, preexec_fn=small_files,
    )
    assert result.returncode == 1
    error = result.stderr.strip().splitlines()[-1]
    assert error.startswith("speechcal export: error: ") and "Traceback" not in result.stderr
    assert "libpng" not in result.stderr  # no line from inside OpenCV before it
    assert str(out) in error and ".partial" not in error  # the folder the user asked for
    assert not out.exists() and _leftovers(tmp_path) == []


def test_bad_session_file_is_one_line_exit_1(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    code, _out, err = _run(capsys, str(bad), "--format", "kalibr", "--out", str(tmp_path / "o"))
    assert code == 1 and err.count("\n") == 1 and str(bad) in err and "not valid JSON" in err
    code, _out, err = _run(capsys, str(tmp_path / "none.json"), "--format", "kalibr",
                           "--out", str(tmp_path / "o"))
    assert code == 1 and "no such session file" in err
    assert not (tmp_path / "o").exists()


def test_missing_recording_names_it_and_what_to_do(session_file, tmp_path, capsys) -> None:
    path = session_file()
    session_json = json.loads(path.read_text())
    session_json["recording"] = ["../nowhere/recording.bag"]
    path.write_text(json.dumps(session_json))
    code, _out, err = _run(capsys, str(path), "--format", "rosbag1", "--out",
                           str(tmp_path / "o"))
    assert code == 1 and err.count("\n") == 1
    assert "recording.bag is missing" in err and "put it back" in err and str(path) in err


def test_no_accepted_sets_is_exit_1(session_file, tmp_path, capsys) -> None:
    path = session_file(decisions=("undecided",))
    code, _out, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(tmp_path / "o"))
    assert code == 1 and "accept sets in the review window first" in err
    code, _out, _err = _run(capsys, str(path), "--format", "kalibr", "--out",
                            str(tmp_path / "o"), "--include-undecided")
    assert code == 0 and (tmp_path / "o" / "cam1").is_dir()


@pytest.mark.parametrize("args", [
    ["--format", "colmap", "--out", "o"],
    ["--format", "kalibr"],
    ["--out", "o"],
])
def test_bad_usage_is_exit_2(args, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["export", "session.json", *args])
    assert exc.value.code == 2


def test_the_recordings_own_folder_is_never_an_output_even_with_force(
    session_file, capsys
) -> None:
    path = session_file()
    folder = Path(load_session(path).recording[0]).parent
    before = sorted(p.name for p in folder.iterdir())
    code, _out, err = _run(capsys, str(path), "--format", "kalibr", "--out", str(folder),
                           "--force")
    assert code == 1 and "choose another output folder" in err
    assert sorted(p.name for p in folder.iterdir()) == before


def test_an_accepted_set_without_frames_is_named_as_left_out(session_file, tmp_path,
                                                             capsys) -> None:
    """A trigger past the recording's end has no frame in any camera: it cannot be
    exported, and the operator is told which set went missing."""
    path = session_file(decisions=("accepted",))
    doc = json.loads(path.read_text())
    last = doc["sets"][-1]
    for frame in last["frames"]:
        frame["index"] = -1
    path.write_text(json.dumps(doc))
    code, stdout, err = _run(capsys, str(path), "--format", "folders", "--out",
                             str(tmp_path / "o"), "--json")
    assert code == 0
    result = json.loads(stdout)
    assert result["sets"] == len(doc["sets"]) - 1
    assert result["skipped"] == [f"set {last['id']}: no camera has a frame at its time"]
    assert f"left out: set {last['id']}: no camera has a frame" in err


def test_accepted_sets_all_without_frames_point_at_the_offset(session_file, tmp_path,
                                                              capsys) -> None:
    """An offset edited far off leaves every set without frames: the message says why
    instead of claiming there are no accepted sets."""
    path = session_file(decisions=("accepted",))
    doc = json.loads(path.read_text())
    for frame_set in doc["sets"]:
        for frame in frame_set["frames"]:
            frame["index"] = -1
    path.write_text(json.dumps(doc))
    code, stdout, err = _run(capsys, str(path), "--format", "kalibr", "--out",
                             str(tmp_path / "o"))
    assert code == 1 and stdout == "" and err.count("\n") == 1
    n = len(doc["sets"])
    assert f"{n} sets to export, but no camera has a frame at their time" in err
    assert "audio offset" in err and not (tmp_path / "o").exists()


def test_a_closed_pipe_neither_stops_an_export_nor_cuts_it_short(session_file, tmp_path):
    """``speechcal export ... 2>&1 | head -1``: the reader gone, the next progress line
    raised BrokenPipeError halfway and the export was thrown away (exit 141, no folder).
    Now what is said goes nowhere and the export is written whole: exit 0 while stdout
    is read, 141 (as for SIGPIPE) when it is the closed pipe too."""
    path = session_file()
    whole = tmp_path / "whole"
    export_session_file(path, "kalibr", whole)

    def files(folder: Path) -> dict[str, bytes]:
        return {str(p.relative_to(folder)): p.read_bytes()
                for p in sorted(folder.rglob("*")) if p.is_file()
                and not p.name.startswith("manifest")}  # they name the folder

    for closed, code in (("stderr", 0), ("both", 141)):
        out = tmp_path / f"closed-{closed}"
        read_end, write_end = os.pipe()
        os.close(read_end)  # the reader is gone before anything is written
        streams = {"stderr": write_end, "stdout": subprocess.PIPE} if closed == "stderr" \
            else {"stderr": write_end, "stdout": write_end}
        try:
            done = subprocess.run(
                [sys.executable, "-m", "speechcal_core.cli", "export", str(path), "--format",
                 "kalibr", "--out", str(out)], **streams, timeout=120)
        finally:
            os.close(write_end)
        assert done.returncode == code, closed
        if closed == "stderr":
            assert done.stdout.decode().startswith("exported 3 frame sets (6 frames, ")
        assert files(out) == files(whole) and len(files(whole)) == 7
        assert (out / "manifest.json").is_file() and (out / "manifest.csv").is_file()
        assert _leftovers(tmp_path) == []
