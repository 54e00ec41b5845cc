"""Find trigger words again from the review: other words, or another sensitivity.

:func:`detect_request` reads what the operator typed ("capture, snapshot", or
"kalibr=K AE L IH B ER" for a word the dictionary lacks) into a checked
:class:`DetectRequest`; :meth:`DetectRequest.run` detects on any thread; the review model
adds the words found that no set covers as new undecided sets
(:meth:`~speechcal_core.review.model.ReviewModel.apply_detected`). The sets already there,
and the decisions on them, stay as they are.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from speechcal_core.errors import UsageError
from speechcal_core.session.model import PRONUNCIATIONS_KEY, SENSITIVITY_KEY, Session
from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechUsageError
from speechcal_core.speech.matching import DEFAULT_SENSITIVITY, TriggerSpec, normalize_word
from speechcal_core.text import new_undecided

Progress = Callable[[str, float], None]

#: how a pronunciation is written, in messages
EXAMPLE = "kalibr=K AE L IH B ER"


@dataclass(frozen=True)
class DetectRequest:
    """Detect ``words`` in the session's audio; a snapshot, review goes on meanwhile."""

    words: tuple[str, ...]
    sensitivity: float
    audio: str
    channel: int | None = None
    pronunciations: Mapping[str, str] = field(default_factory=dict)

    @property
    def text(self) -> str:
        """What the status line says while this runs."""
        return f"finding {quoted(self.words)} in {Path(self.audio).name}…"

    def run(self, progress: Progress | None = None) -> DetectResult:
        """Read the audio and detect; ``progress(text, fraction)`` may raise to cancel
        (it is called from this thread)."""
        from speechcal_core.audio import load_audio
        from speechcal_core.speech import detect_triggers

        report = progress or (lambda _t, _f: None)
        t0 = time.perf_counter()
        report(self.text, 0.0)
        audio = load_audio(self.audio, rate=16000, channel=self.channel)
        report(self.text, 0.1)
        detection = detect_triggers(audio, self.words, sensitivity=self.sensitivity,
                                    pronunciations=self.pronunciations,
                                    progress=lambda f: report(self.text, 0.1 + 0.9 * f))
        report(self.text, 1.0)
        return DetectResult(self, tuple(detection.triggers), tuple(detection.notes),
                            time.perf_counter() - t0)


@dataclass(frozen=True)
class DetectResult:
    """The trigger words found (audio seconds) and the detector's notes."""

    request: DetectRequest
    words: tuple[Word, ...]
    notes: tuple[str, ...] = ()
    seconds: float = 0.0


def parse_trigger_text(text: str) -> tuple[tuple[str, ...], dict[str, str]]:
    """Trigger words and pronunciations from what the operator typed: words separated by
    commas or spaces; ``word=PHONES`` (ARPAbet) gives a word's pronunciation."""
    words: list[str] = []
    prons: dict[str, str] = {}
    for entry in (e.strip() for e in text.split(",")):
        left, has_phones, phones = entry.partition("=")
        plain = [w for w in (normalize_word(x) for x in left.split()) if w]
        if has_phones:  # the last word before "=" takes the phones, up to the comma
            if not plain or not phones.strip():
                raise UsageError(f"“{entry}” gives no word or no phones; write a "
                                 f"pronunciation as {EXAMPLE}")
            prons[plain[-1]] = " ".join(phones.upper().split())
        words += plain
    return tuple(dict.fromkeys(words)), prons


def detect_request(session: Session, text: str, sensitivity: float) -> DetectRequest:
    """A checked request for the words of ``text`` (see :func:`parse_trigger_text`);
    UsageError saying what to type when the words cannot be detected."""
    from speechcal_core.speech.lexicon import pronunciations, spelled_like_hint

    if not session.audio:
        raise UsageError("this session has no audio file to find words in")
    words, prons = parse_trigger_text(text)
    if not words:
        raise UsageError("no trigger word given: type at least one, e.g. capture")
    bad = [w for w in words if not re.fullmatch(r"[\w']+", w)]
    if bad:
        raise UsageError(f"“{bad[0]}” is not a single word: separate words with commas or "
                         "spaces")
    try:
        spec = TriggerSpec(words, sensitivity, prons)
    except SpeechUsageError as exc:
        raise UsageError(str(exc)) from exc
    for word in spec.words:
        try:
            pronunciations(word, dict(spec.pronunciations))
        except SpeechUsageError as exc:
            if word in spec.pronunciations:  # the phones given are wrong
                raise UsageError(str(exc)) from exc
            raise UsageError(
                f"“{word}” is not in the pocketsphinx dictionary: write its pronunciation "
                f"after it in ARPAbet phones, as in {EXAMPLE}{spelled_like_hint(word)}"
            ) from exc
    return DetectRequest(spec.words, spec.sensitivity, session.audio, session.audio_channel,
                         dict(spec.pronunciations))


def detection_settings(session: Session) -> tuple[str, float]:
    """The session's last detection settings as the operator would type them, and its
    sensitivity (the default where the session does not say)."""
    prons = session.extra.get(PRONUNCIATIONS_KEY)
    prons = prons if isinstance(prons, dict) else {}
    text = ", ".join(f"{w}={prons[w]}" if w in prons else w for w in session.triggers_word)
    value = session.extra.get(SENSITIVITY_KEY)
    sensitivity = float(value) if isinstance(value, (int, float)) \
        and not isinstance(value, bool) and 0.0 <= value <= 1.0 else DEFAULT_SENSITIVITY
    return text, sensitivity


#: what :func:`record_settings` changes: the trigger words, sensitivity, pronunciations
Settings = tuple[list[str], object, object]


def settings_of(session: Session) -> Settings:
    """The session's detection settings, for :func:`restore_settings` (an undo)."""
    return (list(session.triggers_word), session.extra.get(SENSITIVITY_KEY),
            session.extra.get(PRONUNCIATIONS_KEY))


def restore_settings(session: Session, settings: Settings) -> None:
    """Put back what :func:`settings_of` gave (a key it found missing is removed)."""
    words, sensitivity, prons = settings
    session.triggers_word = list(words)
    for key, value in ((SENSITIVITY_KEY, sensitivity), (PRONUNCIATIONS_KEY, prons)):
        if value is None:
            session.extra.pop(key, None)
        else:
            session.extra[key] = value


def record_settings(session: Session, request: DetectRequest) -> None:
    """Keep the request's words (first, then the session's others) and settings in the
    session: the next search starts from them, and an added set takes the first word."""
    session.triggers_word = list(dict.fromkeys([*request.words, *session.triggers_word]))
    session.extra[SENSITIVITY_KEY] = request.sensitivity
    prons = session.extra.get(PRONUNCIATIONS_KEY)
    prons = {**(prons if isinstance(prons, dict) else {}), **request.pronunciations}
    if prons:
        session.extra[PRONUNCIATIONS_KEY] = prons


def result_message(result: DetectResult, added: int) -> str:
    """The status line's report of a finished detection (``added`` sets were added)."""
    request = result.request
    found = len(result.words)
    if not found:
        notes = "; ".join(result.notes)
        return notes or f"no {quoted(request.words)} found in {Path(request.audio).name}"
    what = f"found {found} × {quoted(request.words)} at sensitivity {request.sensitivity:.2f}"
    if not added:
        return f"{what}: every one is in the list already"
    known = found - added
    already = f"; {known} already in the list" if known else ""
    sets, them = new_undecided(added)
    return f"{what}: {sets}{already}; accept or reject {them} as usual"


def quoted(words: tuple[str, ...] | list[str]) -> str:
    """Words in quotes, joined: “capture”, “snapshot”."""
    return ", ".join(f"“{w}”" for w in words)
