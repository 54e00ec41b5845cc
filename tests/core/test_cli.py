"""The console script's contract: subcommands, exit codes, errors on stderr."""

from __future__ import annotations

from pathlib import Path

import pytest

from speechcal_core.cli import COMMANDS, build_parser, main


def test_every_designed_subcommand_is_registered() -> None:
    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.dest == "command")
    assert set(subparsers.choices) == set(COMMANDS)
    assert {"synth", "index", "sync", "detect", "process", "export", "review", "demo"} <= set(
        COMMANDS
    )


def test_unknown_subcommand_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["no-such-command"])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_an_option_the_subcommand_lacks_is_reported_with_its_usage(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["process", "rec.bag", "--audio", "a.wav", "-o", "s.json", "--scan"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "usage: speechcal process" in err
    assert "speechcal process: error: unrecognized arguments: --scan" in err


#: metavars of the arguments that name a file or a folder
PATH_METAVARS = {"RECORDING", "AUDIO", "SESSION.json", "SESSION.json | RECORDING",
                 "TARGET.yaml", "F", "DIR", "OUT", "PNG"}


def _path_arguments() -> list[tuple[str, str]]:
    """(command, option string or metavar of a positional) of every path argument."""
    subparsers = next(a for a in build_parser()._actions if a.dest == "command")
    return [(name, action.option_strings[-1] if action.option_strings else action.metavar)
            for name, sub in subparsers.choices.items() for action in sub._actions
            if action.metavar in PATH_METAVARS]


def test_the_path_arguments_are_found() -> None:
    found = _path_arguments()
    assert {("export", "--out"), ("process", "--output"), ("process", "--target"),
            ("process", "--audio"), ("index", "RECORDING"), ("synth", "OUT")} <= set(found)
    assert len(found) >= 20


@pytest.mark.parametrize(("command", "argument"), _path_arguments())
def test_an_empty_file_or_folder_name_is_bad_usage(
        command: str, argument: str, capsys: pytest.CaptureFixture[str]) -> None:
    """An empty name (``--out ""``, an unset shell variable) meant the current folder,
    or for --target and --audio the default, without a word."""
    argv = [command, argument, ""] if argument.startswith("-") else [command, ""]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"speechcal {command}: error: argument " in err
    assert "an empty name; give " in err and "is not taken for the current folder" in err


def test_stage_progress_prints_each_stage_and_every_tenth_not_every_step(capsys) -> None:
    from speechcal_core.cli._output import StageProgress

    report = StageProgress(item_prefixes=("writing ",))
    report("indexing", 0.02)
    for k in range(60, 81):
        report("frames: windows", k / 100)
    report("frames: windows", 0.80)  # the same line again
    for k in range(5):
        report(f"writing cam0/{k}.png", 0.81 + k / 100)
    assert capsys.readouterr().err.splitlines() == [
        "[  2%] indexing", "[ 60%] frames: windows", "[ 70%] frames: windows",
        "[ 80%] frames: windows", "[ 81%] writing cam0/0.png"]


def test_a_reader_that_goes_away_ends_the_command_quietly(tiny_synth) -> None:
    """``speechcal index --json | head``: the pipe closed before the document was written
    ended in a BrokenPipeError traceback; now exit status 141, as for SIGPIPE, and
    nothing on stderr."""
    import os
    import subprocess
    import sys

    folder, truth = tiny_synth
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before anything is written
    try:
        done = subprocess.run([sys.executable, "-m", "speechcal_core.cli", "index",
                               str(folder / truth["recording"]), "--json"],
                              stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write_end)
    assert done.returncode == 141 and done.stderr == ""


def test_file_names_that_are_not_utf8_work_through_index_detect_and_process(
        tiny_synth, tmp_path) -> None:
    """A Latin-1 name (from a FAT card or a zip) crashed in soundfile and the index cache;
    the session file keeps such a name as a JSON escape that reads back as the same name."""
    import json
    import os
    import shutil
    import subprocess
    import sys

    from speechcal_core.session.store import load_session

    folder, truth = tiny_synth
    here = os.fsencode(tmp_path)
    bag, audio = here + b"/r\xe9c.bag", here + b"/aud\xe9o.ogg"
    shutil.copy(folder / truth["recording"], os.fsdecode(bag))
    shutil.copy(folder / "audio.ogg", os.fsdecode(audio))

    def run(*args: bytes) -> subprocess.CompletedProcess:
        done = subprocess.run([sys.executable, "-m", "speechcal_core.cli", *args],
                              capture_output=True, timeout=300)
        assert done.returncode == 0, done.stderr.decode(errors="replace")
        assert b"Traceback" not in done.stderr
        return done

    assert json.loads(run(b"index", bag, b"--json").stdout)["streams"]
    assert json.loads(run(b"detect", audio, b"--json").stdout)
    session = here + b"/s\xe9ssion.json"
    run(b"process", bag, b"--audio", audio, b"-o", session)
    assert b"\\udce9" in Path(os.fsdecode(session)).read_bytes()  # the name escaped
    loaded = load_session(os.fsdecode(session))
    assert loaded.audio == os.fsdecode(audio) and loaded.recording == [os.fsdecode(bag)]


def test_output_that_cannot_be_written_gives_a_one_line_reason(tiny_synth) -> None:
    import subprocess
    import sys

    folder, truth = tiny_synth
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "speechcal_core.cli", "index",
                               str(folder / truth["recording"]), "--json"],
                              stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr == ("speechcal index: error: could not write the output: "
                           "No space left on device\n")


#: modules that take most of a second to import, none of which a usage error needs
HEAVY = ("scipy.signal", "cv2", "rosbags", "pocketsphinx", "PySide6.QtCore")
USAGE_ERRORS = [
    (["synth", "OUT", "--cameras", "20"], "--cameras must be between 1 and 12, got 20"),
    (["synth", "OUT", "--size", "12"], "--size must look like 640x480, got '12'"),
    (["synth", "OUT", "--format", "bogus"], "unknown --format 'bogus'"),
    (["sync", "REC.bag", "--audio", "A.ogg", "--search-s", "-1"],
     "--search-s must be a positive number of seconds, got -1"),
    (["process", "REC.bag", "-o", "S.json"], "a recording needs its audio: add --audio AUDIO"),
    (["review", "REC.bag"], "a recording needs its audio: add --audio AUDIO"),
    (["synth"], "the following arguments are required: OUT"),
    (["synth", "OUT", "--bogus"], "unrecognized arguments: --bogus"),
]


@pytest.mark.parametrize(("argv", "message"), USAGE_ERRORS)
def test_a_usage_error_is_told_before_any_heavy_import(argv, message, tmp_path: Path) -> None:
    """A bad option of synth, sync, process or review took a second or more: scipy.signal
    and the renderer or readers were imported before the options were checked."""
    import json
    import subprocess
    import sys

    probe = ("import json, sys\nfrom speechcal_core.cli import main\n"
             "try:\n    code = main(sys.argv[1:])\nexcept SystemExit as exc:\n"
             "    code = exc.code\n"
             f"print(json.dumps([code, [m for m in {HEAVY!r} if m in sys.modules]]))")
    argv = [str(tmp_path / a) if a in ("OUT", "REC.bag", "A.ogg", "S.json") else a
            for a in argv]
    p = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True, text=True,
                       timeout=60)
    code, imported = json.loads(p.stdout)
    assert code == 2
    assert message in p.stderr.splitlines()[-1]
    assert p.stderr.splitlines()[-1].startswith(f"speechcal {argv[0]}: error: ")
    assert imported == []


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_subcommands_help_imports_nothing_heavy(command: str) -> None:
    import json
    import subprocess
    import sys

    probe = ("import json, sys\nfrom speechcal_core.cli import main\n"
             "try:\n    main(sys.argv[1:])\nexcept SystemExit as exc:\n"
             f"    print(json.dumps([exc.code, [m for m in {HEAVY!r} if m in sys.modules]]))")
    p = subprocess.run([sys.executable, "-c", probe, command, "--help"], capture_output=True,
                       text=True, timeout=60)
    assert p.stdout.startswith(f"usage: speechcal {command}")
    assert json.loads(p.stdout.splitlines()[-1]) == [0, []]



@pytest.mark.parametrize("command", ["process", "review"])
@pytest.mark.parametrize("option", ["--stream", "--skip-stream"])
def test_an_empty_stream_name_is_bad_usage(command: str, option: str, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    """An empty topic (an unset shell variable) was looked up after indexing the whole
    recording, then refused as a stream the recording lacks. Parsed only: a review that
    got past its arguments would open the window."""
    argv = [command, str(tmp_path / "not-indexed.bag"), "--audio", "a.ogg", option, " "]
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv + (["-o", "s.json"] if command == "process" else []))
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"speechcal {command}: error: argument {option}: an empty stream name" in err
    assert "speechcal index RECORDING" in err
