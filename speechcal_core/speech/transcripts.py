"""Import timed words from existing transcripts: WhisperX, faster-whisper, Audacity, CSV,
and openai-whisper's TSV."""

from __future__ import annotations

import codecs
import csv
import io
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechError

FORMATS = ("WhisperX JSON, faster-whisper JSON, Audacity labels (.txt), openai-whisper "
           "TSV or CSV word,start,end")
#: a subtitle cue's timing line (SRT "00:00:06,885 --> ...", WebVTT "00:06.885 --> ...")
_CUE = re.compile(r"^\s*(\d+:)?\d+:\d+[,.]\d+\s+-->\s+")


@dataclass
class Transcript:
    """Words read from a transcript, plus the words that carried no usable time."""

    path: Path
    format: str
    words: list[Word] = field(default_factory=list)
    untimed: list[str] = field(default_factory=list)
    early: list[str] = field(default_factory=list)  # words timed before the audio's start
    #: words timed past any audio (the session's MAX_AUDIO_S: times in nanoseconds?)
    late: list[str] = field(default_factory=list)
    repeated: int = 0  # words listed twice at the same times, taken once

    def note(self) -> str | None:
        """A one-line report of skipped words, or None when every word was taken."""
        parts = []
        if self.untimed:
            parts.append(f"{len(self.untimed)} word(s) without timestamps (none, or an end "
                         f"before the start) skipped ({_shown(self.untimed)})")
        if self.early:
            parts.append(f"{len(self.early)} word(s) timed before the audio's start "
                         f"(negative times) skipped ({_shown(self.early)}); is it this "
                         "audio's transcript, with times in seconds?")
        if self.late:
            parts.append(f"{len(self.late)} word(s) timed past any audio (over 31 years) "
                         f"skipped ({_shown(self.late)}); is it this audio's transcript, "
                         "with times in seconds?")
        if self.repeated:
            parts.append(f"{self.repeated} word(s) listed twice at the same times, taken "
                         "once")
        return f"{self.path}: {'; '.join(parts)}" if parts else None

    def checked(self) -> Transcript:
        """This transcript with words timed before zero or past any audio set aside and
        repeats dropped."""
        from speechcal_core.session.model import MAX_AUDIO_S

        seen: set[tuple[str, float, float]] = set()
        kept = []
        for word in self.words:
            key = (word.word.lower(), word.start_s, word.end_s)
            if word.start_s < 0:
                self.early.append(word.word)
            elif word.end_s >= MAX_AUDIO_S:
                self.late.append(word.word)
            elif key in seen:
                self.repeated += 1
            else:
                seen.add(key)
                kept.append(word)
        self.words = kept
        return self


def _shown(words: list[str]) -> str:
    """The first five words, quoted, and how many more."""
    more = f" and {len(words) - 5} more" if len(words) > 5 else ""
    return ", ".join(repr(w) for w in words[:5]) + more


def _decoded(raw: bytes) -> str:
    """Text of a transcript file: UTF-8, or UTF-16 where it opens with a byte-order mark
    (a spreadsheet's "Unicode text")."""
    if raw[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        return raw.decode("utf-16")
    return raw.decode("utf-8-sig")


def read_transcript(path: str | Path) -> Transcript:
    """Read a transcript file, detecting its format from the content."""
    p = Path(path)
    if not p.is_file():
        raise SpeechError(f"{p}: transcript not found; check the path given with --transcript")
    try:
        text = _decoded(p.read_bytes())
    except (OSError, UnicodeDecodeError) as exc:
        from speechcal_core.sources.sniff import looks_like

        seen = looks_like(p) if isinstance(exc, UnicodeDecodeError) else ""
        if seen:  # the audio or the recording given in its place
            raise SpeechError(f"{p}: this is {seen.split(' (')[0]}, not a transcript; give "
                              f"--transcript a transcript with word times ({FORMATS})") \
                from exc
        raise SpeechError(f"{p}: cannot read the transcript ({exc}); save it as UTF-8 text") \
            from exc
    if not text.strip():
        raise SpeechError(f"{p}: the transcript is empty; export it again with word timestamps")
    stripped = text.lstrip()  # blank lines before a header are no row
    if stripped[:1] in "[{":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SpeechError(f"{p}: broken JSON at line {exc.lineno} ({exc.msg}); "
                              f"export the transcript again") from exc
        return _from_json(p, data).checked()
    lines = stripped.splitlines()
    if lines[0].strip().startswith("WEBVTT") or any(_CUE.match(ln) for ln in lines[:4]):
        raise SpeechError(f"{p}: subtitles (SRT or WebVTT) time whole lines, not words; give "
                          f"a transcript with word times ({FORMATS})")
    first = lines[0]
    if "\t" in first:
        header = [c.strip().lower() for c in first.split("\t")]
        if header == ["start", "end", "text"]:
            return _from_whisper_tsv(p, stripped).checked()
        if any(h in names for h in header for names in CSV_COLUMNS) or _word_first(header):
            return _from_csv(p, stripped, delimiter="\t").checked()
        return _from_audacity(p, stripped).checked()
    if first.count(";") >= 2:  # a spreadsheet's CSV where the decimal mark is a comma
        return _from_csv(p, stripped, delimiter=";").checked()
    return _from_csv(p, stripped).checked()


def _word_first(cells: list[str]) -> bool:
    """Whether a tab-separated row reads word, start, end (a word table without its
    header) rather than Audacity's start, end, label."""
    return (len(cells) >= 3 and _number(cells[0]) is None
            and _number(cells[1]) is not None and _number(cells[2]) is not None)


def _from_json(p: Path, data: Any) -> Transcript:
    """WhisperX (``word_segments`` or ``segments[].words``) or a faster-whisper word list."""
    if isinstance(data, dict) and isinstance(data.get("word_segments"), list):
        return _word_list(p, "whisperx", data["word_segments"])
    if isinstance(data, dict) and isinstance(data.get("segments"), list):
        items = []
        for seg in data["segments"]:
            if isinstance(seg, dict) and isinstance(seg.get("words"), list):
                items.extend(seg["words"])
        if not items and data["segments"]:
            raise SpeechError(f"{p}: segments carry no word timings; transcribe again with "
                              f"word timestamps (WhisperX align, faster-whisper "
                              f"word_timestamps=True)")
        return _word_list(p, "whisperx", items)
    if isinstance(data, dict) and isinstance(data.get("words"), list):
        return _word_list(p, "faster-whisper", data["words"])
    if isinstance(data, list):
        items = []
        for entry in data:  # a list of segments with words, or of words
            if isinstance(entry, dict) and isinstance(entry.get("words"), list):
                items.extend(entry["words"])
            else:
                items.append(entry)
        return _word_list(p, "faster-whisper", items)
    raise SpeechError(f"{p}: JSON without word timings; expected {FORMATS}")


def _word_list(p: Path, fmt: str, items: list) -> Transcript:
    """Words as dicts (``word``/``text``, ``start``, ``end``, optional ``score``/
    ``probability``) or faster-whisper style ``[start, end, word, probability]`` lists."""
    out = Transcript(p, fmt)
    for item in items:
        if isinstance(item, dict):
            text = item.get("word", item.get("text"))
            start, end = item.get("start"), item.get("end")
            score = item.get("score", item.get("probability", 1.0))
        elif isinstance(item, (list, tuple)) and len(item) >= 3:
            start, end, text = item[0], item[1], item[2]
            score = item[3] if len(item) > 3 else 1.0
        else:
            continue
        if text is None:
            continue
        text = str(text).strip()
        t0, t1 = _number(start), _number(end)
        if t0 is None or t1 is None or t1 < t0:
            out.untimed.append(text)
            continue
        out.words.append(Word(text, t0, t1, _number(score) or 0.0, fmt))
    return out


def _from_audacity(p: Path, text: str) -> Transcript:
    """Audacity label track: ``start<TAB>end<TAB>label``; ``\\`` frequency lines ignored."""
    out = Transcript(p, "audacity")
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.startswith("\\"):
            continue
        parts = line.split("\t")
        if len(parts) < 3:
            raise SpeechError(f"{p}: line {n} is not 'start<TAB>end<TAB>label'; export the "
                              f"label track again from Audacity")
        t0, t1 = _number(parts[0]), _number(parts[1])
        label = parts[2].strip()
        for word in label.split() or [""]:
            if t0 is None or t1 is None or t1 < t0:
                out.untimed.append(word)
            elif word:
                out.words.append(Word(word, t0, t1, 1.0, "audacity"))
    return out


def _from_whisper_tsv(p: Path, text: str) -> Transcript:
    """openai-whisper's ``--output_format tsv``: ``start<TAB>end<TAB>text`` under that
    header, times in whole milliseconds; a line's words share its times. Times with a
    fraction are seconds (a table written by hand under the same header): read as
    milliseconds, every word fell in the audio's first hundredth of a second."""
    rows = []
    for n, line in enumerate(text.splitlines()[1:], 2):
        if not line.strip():
            continue
        parts = line.split("\t", 2)
        if len(parts) < 3:
            raise SpeechError(f"{p}: line {n} is not 'start<TAB>end<TAB>text'; write the "
                              "transcript again with whisper's --output_format tsv")
        rows.append((_number(parts[0]), _number(parts[1]), parts[2].split()))
    times = [t for t0, t1, _ in rows for t in (t0, t1) if t is not None]
    seconds = any(not t.is_integer() for t in times)
    out = Transcript(p, "tsv" if seconds else "whisper-tsv")
    unit = 1.0 if seconds else 1000.0
    for t0, t1, words in rows:
        for word in words:
            if t0 is None or t1 is None or t1 < t0:
                out.untimed.append(word)
            else:
                out.words.append(Word(word, t0 / unit, t1 / unit, 1.0, out.format))
    return out


#: header names of the CSV's word, start and end columns
CSV_COLUMNS = (("word", "text", "label"), ("start", "begin", "start_s"), ("end", "stop", "end_s"))


def _from_csv(p: Path, text: str, delimiter: str = ",") -> Transcript:
    """CSV ``word,start,end`` (a header row is optional and may name the columns in any
    order, also as text/label, begin, stop; extra columns ignored); tab-separated too."""
    out = Transcript(p, "csv")
    try:
        rows = list(csv.reader(io.StringIO(text), delimiter=delimiter))
    except csv.Error as exc:  # a quote left open swallows the rest into one field
        raise SpeechError(f"{p}: not a readable CSV ({exc}: a quote left open?); "
                          "give a CSV of word,start,end") from exc
    backwards = 0  # rows whose times are numbers, the end before the start
    header = [c.strip().lower() for c in rows[0]] if rows else []
    cols = (0, 1, 2)
    other_header = False
    named = [next((header.index(n) for n in names if n in header), None)
             for names in CSV_COLUMNS]
    if all(k is not None for k in named):
        cols = tuple(named)  # type: ignore[assignment]
        rows = rows[1:]
    elif rows and _number(rows[0][1] if len(rows[0]) > 1 else None) is None:
        rows, other_header = rows[1:], True  # some other header
    for n, row in enumerate(rows, 1):
        if not row or not "".join(row).strip():
            continue
        if len(row) <= max(cols):
            raise SpeechError(f"{p}: row {n} has {len(row)} column(s); expected word,start,end")
        word = row[cols[0]].strip()
        t0, t1 = _number(row[cols[1]]), _number(row[cols[2]])
        if t0 is None or t1 is None or t1 < t0:
            out.untimed.append(word)
            backwards += t0 is not None and t1 is not None
        else:
            out.words.append(Word(word, t0, t1, 1.0, "csv"))
    if out.untimed and not out.words and backwards == len(out.untimed):
        raise SpeechError(f"{p}: every row's end comes before its start (the first reads "
                          f"{','.join(rows[0])!r}); the columns are word,start,end")
    if out.untimed and not out.words:  # columns in another order, or no times at all
        raise SpeechError(
            f"{p}: no row has a word with start and end times (the first reads "
            f"{','.join(rows[0]) if rows else ''!r}); the columns must be word,start,end, "
            f"or name them so in a header row")
    if other_header and not out.words and not out.untimed:
        raise SpeechError(
            f"{p}: not a transcript (no rows of word,start,end); give a WhisperX or "
            f"faster-whisper JSON, an Audacity label track or a CSV of word,start,end")
    return out


#: a number written with a decimal comma (a spreadsheet's or Audacity's in some locales)
_DECIMAL_COMMA = re.compile(r"[-+]?\d+,\d+")


def _number(value: Any) -> float | None:
    """A finite float (also one written with a decimal comma, "6,460000"), or None for
    missing/blank/non-numeric values."""
    if value is None or isinstance(value, bool):
        return None
    if not isinstance(value, (int, float)):
        value = str(value).strip()
        if _DECIMAL_COMMA.fullmatch(value):
            value = value.replace(",", ".")
    try:
        x = float(value)
    except ValueError:
        return None
    return x if x == x and abs(x) != float("inf") else None


class TranscriptBackend:
    """A backend that reads words from a transcript instead of listening."""

    name = "transcript"

    def __init__(self, path: str | Path) -> None:
        self.transcript = read_transcript(path)

    def words(self, audio: object, spec: object) -> list[Word]:
        """The transcript's timed words (``audio`` and ``spec`` are not needed)."""
        return list(self.transcript.words)
