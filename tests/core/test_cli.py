"""The console script's contract: subcommands, exit codes, errors on stderr."""

from __future__ import annotations

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
