"""Base error type; every layer raises a subclass whose message names the file and the fix."""

from __future__ import annotations


class SpeechCalError(Exception):
    """Bad input or a failed step, with a one-line message meant for the operator."""


class UsageError(SpeechCalError):
    """The request itself is wrong (bad option value); the CLI exits with code 2."""


class NotYetAvailableError(UsageError):
    """A subcommand or feature that this version does not provide yet."""
