"""Trigger-word options shared by ``detect``, ``process`` and ``review``."""

from __future__ import annotations

import argparse

from speechcal_core.errors import UsageError
from speechcal_core.speech.matching import (
    DEFAULT_SENSITIVITY,
    DEFAULT_TRIGGERS,
    normalize_word,
)


def add_channel_option(p: argparse.ArgumentParser) -> None:
    """``--channel N``: one channel of a multi-channel audio file (sync, detect, process)."""
    p.add_argument("--channel", type=int, default=None, metavar="N",
                   help="use this audio channel (0-based) instead of mixing all")


def add_trigger_options(p: argparse.ArgumentParser) -> None:
    """``--trigger``, ``--sensitivity`` and ``--pronounce``."""
    p.add_argument("--trigger", action="append", metavar="W", help="trigger word (repeatable)")
    p.add_argument("--sensitivity", type=float, default=DEFAULT_SENSITIVITY, metavar="S",
                   help="0..1; higher finds more words and more false alarms "
                        f"(default {DEFAULT_SENSITIVITY:g})")
    p.add_argument("--pronounce", action="append", default=[], metavar="WORD=PHONES",
                   help="ARPAbet pronunciation of a word missing from the dictionary, or "
                        "one more for a word it has (an accent)")


def detection_options_given(args: argparse.Namespace) -> bool:
    """Whether any of ``add_trigger_options``' and ``add_channel_option``'s options was
    given (differs from its default)."""
    return bool(args.trigger or args.pronounce or args.channel is not None
                or args.sensitivity != DEFAULT_SENSITIVITY)


def pronunciations(args: argparse.Namespace) -> dict[str, str]:
    """``--pronounce WORD=PHONES`` options as a mapping; UsageError for a malformed one."""
    out = {}
    for item in args.pronounce:
        word, sep, phones = item.partition("=")
        if not sep or not word.strip() or not phones.strip():
            raise UsageError(
                f"--pronounce {item!r}: write WORD=PHONES, e.g. 'kalibr=K AE L IH B ER'"
            )
        out[word.strip()] = phones.strip()
    triggers = {normalize_word(w) for w in (args.trigger or DEFAULT_TRIGGERS)}
    unused = [w for w in out if normalize_word(w) not in triggers]
    if unused:
        raise UsageError(
            f"--pronounce {unused[0]}: not one of the trigger words "
            f"({', '.join(sorted(triggers))}), so it would not be used; give it with "
            f"--trigger {unused[0]} too, or check its spelling")
    return out


def sensitivity(args: argparse.Namespace) -> float:
    """``--sensitivity``, checked to lie in 0..1."""
    if not 0.0 <= args.sensitivity <= 1.0:
        raise UsageError(f"--sensitivity {args.sensitivity:g}: give a value from 0 to 1")
    return args.sensitivity
