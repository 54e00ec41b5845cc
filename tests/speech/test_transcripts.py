"""Transcript import: WhisperX, faster-whisper, Audacity labels, openai-whisper TSV, CSV."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from speechcal_core.speech import SpeechError, detect_triggers
from speechcal_core.speech.transcripts import read_transcript


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_whisperx_word_segments_report_words_without_timestamps(tmp_path: Path) -> None:
    doc = {"segments": [], "word_segments": [
        {"word": "Capture!", "start": 1.0, "end": 1.5, "score": 0.9},
        {"word": "42"},  # WhisperX leaves numerals unaligned
        {"word": "capture", "start": 3.0, "end": 3.4},
    ]}
    p = _write(tmp_path, "wx.json", json.dumps(doc))
    t = read_transcript(p)
    assert t.format == "whisperx"
    assert [(w.word, w.start_s) for w in t.words] == [("Capture!", 1.0), ("capture", 3.0)]
    assert t.untimed == ["42"]
    result = detect_triggers(None, ["capture"], transcript=p)
    assert [w.t for w in result.triggers] == [1.25, 3.2]
    assert any("1 word(s) without timestamps" in n for n in result.notes)


def test_whisperx_segment_words_are_read(tmp_path: Path) -> None:
    doc = {"segments": [{"start": 0.5, "end": 2.0, "text": "ok capture",
                         "words": [{"word": "ok", "start": 0.5, "end": 0.7},
                                   {"word": "capture", "start": 1.0, "end": 1.6}]}]}
    t = read_transcript(_write(tmp_path, "wx.json", json.dumps(doc)))
    assert [w.word for w in t.words] == ["ok", "capture"]


def test_faster_whisper_word_lists_are_read(tmp_path: Path) -> None:
    dicts = [{"start": 1.0, "end": 1.4, "word": " Capture", "probability": 0.8}]
    tuples = [[2.0, 2.5, " capture", 0.7], [3.0, None, " capture", 0.5]]
    assert read_transcript(_write(tmp_path, "a.json", json.dumps(dicts))).words[0].score == 0.8
    t = read_transcript(_write(tmp_path, "b.json", json.dumps(tuples)))
    assert [w.start_s for w in t.words] == [2.0]
    assert t.untimed == ["capture"]


def test_audacity_labels_and_csv_are_read(tmp_path: Path) -> None:
    labels = "1.000000\t1.500000\tCapture\n\\\t300.0\t3000.0\n4.0\t4.4\tcaptured\n"
    t = read_transcript(_write(tmp_path, "labels.txt", labels))
    assert [(w.word, w.end_s) for w in t.words] == [("Capture", 1.5), ("captured", 4.4)]
    csv_text = "word,start,end\ncapture,1.0,1.5\nhello,,\ncapture,2,2.5\n"
    t = read_transcript(_write(tmp_path, "words.csv", csv_text))
    assert [w.start_s for w in t.words] == [1.0, 2.0]
    assert t.untimed == ["hello"]
    reordered = "Start,End,Text,Speaker\n1.0,1.5,capture,A\n2.0,2.5,Capture!,A\n"
    t = read_transcript(_write(tmp_path, "reordered.csv", reordered))
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [("capture", 1.0, 1.5),
                                                                ("Capture!", 2.0, 2.5)]


def test_whisper_tsv_in_milliseconds_and_tab_separated_words_with_a_header(
        tmp_path: Path) -> None:
    """openai-whisper's TSV was read as Audacity labels (6885 s!), and a tab-separated
    word/start/end table listed its header as skipped words."""
    tsv = "start\tend\ttext\n6885\t7513\tCapture.\n9000\t9400\tcapture now\n"
    t = read_transcript(_write(tmp_path, "talk.tsv", tsv))
    assert t.format == "whisper-tsv"
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [
        ("Capture.", 6.885, 7.513), ("capture", 9.0, 9.4), ("now", 9.0, 9.4)]
    table = "word\tstart\tend\ncapture\t6.885\t7.513\n"
    t = read_transcript(_write(tmp_path, "words.tsv", table))
    assert [(w.word, w.start_s) for w in t.words] == [("capture", 6.885)] and not t.untimed


def test_a_tab_separated_word_table_without_a_header_is_not_read_as_audacity_labels(
        tmp_path: Path) -> None:
    """Its words were taken for untimed labels and every trigger was lost."""
    rows = "capture\t6.6\t7.16\ncapture\t9.26\t10.04\n"
    t = read_transcript(_write(tmp_path, "words.tsv", rows))
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [
        ("capture", 6.6, 7.16), ("capture", 9.26, 10.04)] and not t.untimed
    labels = "6.6\t7.16\tcapture\n9.26\t10.04\tcapture\n"  # Audacity's order still
    t = read_transcript(_write(tmp_path, "labels.txt", labels))
    assert t.format == "audacity" and [w.start_s for w in t.words] == [6.6, 9.26]


@pytest.mark.parametrize("text", [
    "word;start;end\ncapture;1,25;1,5\nok;2;2,5\n",  # a spreadsheet's CSV (de, fr)
    "capture;1,25;1,5\nok;2;2,5\n",
    "1,250000\t1,500000\tcapture\n2,000000\t2,500000\tok\n",  # Audacity in such a locale
])
def test_times_with_a_decimal_comma_are_read(tmp_path: Path, text: str) -> None:
    """They were words "without timestamps", skipped, and no trigger word was found."""
    t = read_transcript(_write(tmp_path, "words.csv", text))
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [("capture", 1.25, 1.5),
                                                                 ("ok", 2.0, 2.5)]
    assert t.note() is None


@pytest.mark.parametrize("text", [
    "\n\nword,start,end\ncapture,1.25,1.5\n",
    "\n\nword\tstart\tend\ncapture\t1.25\t1.5\n",
    "\r\nstart\tend\ttext\n1250\t1500\tcapture\n",
])
def test_blank_lines_before_a_header_leave_it_a_header(tmp_path: Path, text: str) -> None:
    """The header was read as a word without timestamps, and said so."""
    t = read_transcript(_write(tmp_path, "words.csv", text))
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [("capture", 1.25, 1.5)]
    assert t.note() is None


def test_words_before_the_audio_and_words_listed_twice_are_noted(tmp_path: Path) -> None:
    rows = "capture,-3.0,-2.5\ncapture,1.0,1.5\ncapture,1.0,1.5\nCapture,4.0,4.5\n"
    t = read_transcript(_write(tmp_path, "shifted.csv", rows))
    assert [w.start_s for w in t.words] == [1.0, 4.0]
    note = t.note()
    assert note is not None and note.startswith(f"{tmp_path / 'shifted.csv'}: ")
    assert "1 word(s) timed before the audio's start (negative times) skipped" in note
    assert "is it this audio's transcript, with times in seconds?" in note
    assert "1 word(s) listed twice at the same times, taken once" in note


@pytest.mark.parametrize("text, fix", [
    ("1\n00:00:06,885 --> 00:00:07,513\nCapture.\n", "subtitles"),
    ("WEBVTT\n\n00:06.885 --> 00:07.513\nCapture.\n", "time whole lines, not words"),
    ("capture,3.0,1.0\ncapture,9.0,8.5\n", "every row's end comes before its start"),
    ("", "empty"),
    ("{not json", "broken JSON"),
    ('{"text": "capture"}', "without word timings"),
    ("1.0\tcapture\n", "start<TAB>end<TAB>label"),
    ("hello\n", "not a transcript"),  # one word of plain text: no header, no rows
    ("from,to,what\n1.0,1.5,capture\n2.0,2.5,capture\n", "columns must be word,start,end"),
    ('"capture,1.0,1.5\n' + "capture,2.0,2.5\n" * 10_000, "a quote left open"),
])
def test_bad_transcripts_name_the_file_and_the_fix(tmp_path: Path, text: str, fix: str) -> None:
    p = _write(tmp_path, "bad.txt", text)
    with pytest.raises(SpeechError, match=fix) as exc:
        read_transcript(p)
    assert str(p) in str(exc.value)


def test_a_start_end_text_table_in_seconds_is_read_in_seconds(tmp_path: Path) -> None:
    """Under whisper's TSV header, times were taken for milliseconds whatever they were:
    6.46 s became 0.00646 s, without a word."""
    text = "start\tend\ttext\n6.46\t6.875\tcapture\n8\t8.5\tok capture\n"
    t = read_transcript(_write(tmp_path, "words.tsv", text))
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [
        ("capture", 6.46, 6.875), ("ok", 8.0, 8.5), ("capture", 8.0, 8.5)]


def test_the_audio_given_as_the_transcript_is_named_as_audio(tmp_path: Path) -> None:
    """Swapped arguments: the audio was "a transcript to save as UTF-8 text"."""
    import numpy as np
    import soundfile as sf

    audio = tmp_path / "mic.flac"
    sf.write(audio, np.zeros(16000, np.float32), 16000)
    with pytest.raises(SpeechError) as exc:
        read_transcript(audio)
    assert str(exc.value) == (
        f"{audio}: this is a FLAC audio file, not a transcript; give --transcript a "
        "transcript with word times (WhisperX JSON, faster-whisper JSON, Audacity labels "
        "(.txt), openai-whisper TSV or CSV word,start,end)")


def test_missing_transcript_names_the_option(tmp_path: Path) -> None:
    with pytest.raises(SpeechError, match="--transcript"):
        read_transcript(tmp_path / "nope.json")


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_a_table_saved_as_unicode_text_is_read(tmp_path: Path, encoding: str) -> None:
    """Spreadsheets save "Unicode text" as UTF-16 with a byte-order mark."""
    p = tmp_path / "words.txt"
    text = "word\tstart\tend\r\nCapture!\t1.0\t1.5\r\nok\t2.0\t2.2\r\n"
    p.write_bytes(("\ufeff" + text).encode(encoding) if encoding.endswith("be")
                  else text.encode(encoding))
    t = read_transcript(p)
    assert [(w.word, w.start_s, w.end_s) for w in t.words] == [
        ("Capture!", 1.0, 1.5), ("ok", 2.0, 2.2)]


def test_words_timed_past_any_audio_are_skipped_and_noted(tmp_path: Path) -> None:
    """Times in nanoseconds (or a typo) lie decades past any audio: a session made from
    them could not be opened again, so they are set aside as negative times are."""
    rows = "capture,1.0,1.5\ncapture,1e10,1.00000001e10\ncapture,1.2e19,1.3e19\n"
    t = read_transcript(_write(tmp_path, "ns.csv", rows))
    assert [w.start_s for w in t.words] == [1.0]
    note = t.note()
    assert note is not None
    assert "2 word(s) timed past any audio (over 31 years) skipped" in note
    assert "is it this audio's transcript, with times in seconds?" in note
