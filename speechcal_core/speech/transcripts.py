"""Import timed words from existing transcripts: WhisperX, faster-whisper, Audacity, CSV."""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechError

FORMATS = "WhisperX JSON, faster-whisper JSON, Audacity labels (.txt) or CSV word,start,end"


@dataclass
class Transcript:
    """Words read from a transcript, plus the words that carried no usable time."""

    path: Path
    format: str
    words: list[Word] = field(default_factory=list)
    untimed: list[str] = field(default_factory=list)

    def note(self) -> str | None:
        """A one-line report of skipped words, or None when every word was timed."""
        if not self.untimed:
            return None
        shown = ", ".join(repr(w) for w in self.untimed[:5])
        more = f" and {len(self.untimed) - 5} more" if len(self.untimed) > 5 else ""
        return (f"{self.path}: {len(self.untimed)} word(s) without timestamps (none, or "
                f"an end before the start) skipped ({shown}{more})")


def read_transcript(path: str | Path) -> Transcript:
    """Read a transcript file, detecting its format from the content."""
    p = Path(path)
    if not p.is_file():
        raise SpeechError(f"{p}: transcript not found; check the path given with --transcript")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpeechError(f"{p}: cannot read the transcript ({exc}); save it as UTF-8 text") \
            from exc
    if not text.strip():
        raise SpeechError(f"{p}: the transcript is empty; export it again with word timestamps")
    stripped = text.lstrip()
    if stripped[:1] in "[{":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SpeechError(f"{p}: broken JSON at line {exc.lineno} ({exc.msg}); "
                              f"export the transcript again") from exc
        return _from_json(p, data)
    first = stripped.splitlines()[0]
    if "\t" in first:
        return _from_audacity(p, text)
    return _from_csv(p, text)


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


#: header names of the CSV's word, start and end columns
CSV_COLUMNS = (("word", "text", "label"), ("start", "begin", "start_s"), ("end", "stop", "end_s"))


def _from_csv(p: Path, text: str) -> Transcript:
    """CSV ``word,start,end`` (a header row is optional and may name the columns in any
    order, also as text/label, begin, stop; extra columns ignored)."""
    out = Transcript(p, "csv")
    rows = list(csv.reader(io.StringIO(text)))
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
        else:
            out.words.append(Word(word, t0, t1, 1.0, "csv"))
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


def _number(value: Any) -> float | None:
    """A finite float, or None for missing/blank/non-numeric values."""
    if value is None or isinstance(value, bool):
        return None
    try:
        x = float(str(value).strip()) if not isinstance(value, (int, float)) else float(value)
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
