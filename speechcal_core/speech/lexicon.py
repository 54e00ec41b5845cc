"""The pocketsphinx pronunciation dictionary: look-ups, user pronunciations, confusable words."""

from __future__ import annotations

import difflib
import functools
import math
import re
from collections import Counter
from pathlib import Path

from speechcal_core.speech.errors import SpeechUsageError

#: the phones of the bundled en-us acoustic model (CMU ARPAbet, no stress marks)
PHONES = frozenset((
    "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G",
    "HH", "IH", "IY", "JH", "K", "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T",
    "TH", "UH", "UW", "V", "W", "Y", "Z", "ZH",
))
#: at most this many phones added around a trigger's pronunciation still makes it a rival
MAX_EXTRA_PHONES = 3
MAX_RIVALS = 250
#: rivals are words people say: known to the language model above this unigram log10 p
MIN_UNIGRAM_LOG10 = -7.0

#: "record(2)": an entry for a word's second (third...) pronunciation
ALTERNATE_SUFFIX = re.compile(r"\(\d+\)$")

Pron = tuple[str, ...]


def model_dir() -> Path:
    """Folder of pocketsphinx's bundled en-us model."""
    import pocketsphinx

    return Path(pocketsphinx.get_model_path()) / "en-us"


@functools.lru_cache(maxsize=2)
def load_dictionary(path: str | None = None) -> dict[str, tuple[Pron, ...]]:
    """Word -> pronunciations of the CMU dictionary (alternates like ``word(2)`` merged)."""
    p = Path(path) if path else model_dir() / "cmudict-en-us.dict"
    entries: dict[str, list[Pron]] = {}
    with open(p, encoding="utf-8", errors="replace") as f:
        for line in f:
            parts = line.split()
            if len(parts) < 2:
                continue
            entries.setdefault(dictionary_word(parts[0]), []).append(tuple(parts[1:]))
    return {w: tuple(ps) for w, ps in entries.items()}


def dictionary_word(entry: str) -> str:
    """The word a dictionary entry (or a decoded word) spells: "record(2)", the
    dictionary's second pronunciation of "record", is "record"."""
    return ALTERNATE_SUFFIX.sub("", entry) if entry.endswith(")") else entry


def parse_phones(word: str, phones: str) -> Pron:
    """Validate a user pronunciation such as ``"K AE P CH ER"`` (stress digits dropped)."""
    pron = tuple(re.sub(r"\d", "", p) for p in phones.upper().split())
    bad = [p for p in pron if p not in PHONES]
    if not pron or bad:
        raise SpeechUsageError(
            f"pronunciation of {word!r} ({phones!r}) uses unknown phones {bad or '(none)'}; "
            f"use ARPAbet phones: {' '.join(sorted(PHONES))}"
        )
    return pron


def pronunciations(word: str, user: dict[str, str] | None = None) -> tuple[Pron, ...]:
    """The pronunciations of ``word``: the user's first if given, then the dictionary's.

    Raises SpeechError naming the word and how to supply a pronunciation.
    """
    found = load_dictionary().get(word)
    if user and word in user:
        mine = parse_phones(word, user[word])
        return (mine, *(p for p in found or () if p != mine))
    if not found:
        raise SpeechUsageError(
            f"trigger word {word!r} is not in the pocketsphinx dictionary; give its "
            f"pronunciation in ARPAbet phones, as --pronounce '{word}=PHONES'"
            f"{spelled_like_hint(word)}"
        )
    return found


def spelled_like(word: str, n: int = 2) -> list[tuple[str, Pron]]:
    """Up to ``n`` dictionary words spelled most like ``word``, with their first
    pronunciation: a start for writing the pronunciation of a word it lacks."""
    words = load_dictionary()
    return [(w, words[w][0]) for w in difflib.get_close_matches(word, words, n=n, cutoff=0.7)]


def spelled_like_hint(word: str) -> str:
    """"; the dictionary has calibrate = K AE L AH B R EY T, ..." for the words spelled like
    ``word``, or how a known word is written when none is."""
    close = spelled_like(word)
    shown = close or [("capture", load_dictionary()["capture"][0])]
    return (f"; the dictionary {'has' if close else 'writes'} "
            + ", ".join(f"{w} = {' '.join(pron)}" for w, pron in shown))


def rival_words(prons: tuple[Pron, ...], exclude: set[str]) -> list[str]:
    """Dictionary words a detector must tell apart from a trigger word.

    Words that start with a trigger pronunciation and add a few phones (inflections such
    as "captured"). One-phone neighbours are no rivals: in noise the model lets "captor"
    or "rapture" win over a real "capture" too often (recall fell from 0.88 to 0.78 at
    10 dB while precision rose by 0.03); the phone loop still competes with them.
    Words that add phones in front ("nightclubs" for "clubs") are left out: in running
    speech the word before would lend them those phones.
    """
    return list(_rivals(tuple(sorted(prons)), tuple(sorted(exclude))))


@functools.lru_cache(maxsize=16)
def _rivals(prons: tuple[Pron, ...], exclude: tuple[str, ...]) -> tuple[str, ...]:
    scored: list[tuple[int, str]] = []
    common = _common_words()
    for word, alts in load_dictionary().items():
        if word in exclude or word not in common:
            continue
        best = None
        for alt in alts:
            for pron in prons:
                d = _rival_distance(pron, alt)
                if d is not None and (best is None or d < best):
                    best = d
        if best is not None:
            scored.append((best, word))
    scored.sort()
    return tuple(w for _, w in scored[:MAX_RIVALS])


@functools.lru_cache(maxsize=1)
def _common_words() -> frozenset[str]:
    """Dictionary words the bundled language model knows with a unigram log10 p > -7."""
    return frozenset(_unigram_log10())


@functools.lru_cache(maxsize=1)
def _unigram_log10() -> dict[str, float]:
    """log10 p of each dictionary word in the bundled language model, for the words it
    knows with a log10 p above MIN_UNIGRAM_LOG10."""
    import pocketsphinx

    logmath = pocketsphinx.LogMath()
    lm = pocketsphinx.NGramModel(pocketsphinx.Config(lm=None, loglevel="ERROR"), logmath,
                                 str(model_dir() / "en-us.lm.bin"))
    per_log10 = logmath.log(10.0)
    out = {}
    for w in load_dictionary():
        if w.replace("'", "").isalpha():
            p = lm.prob([w]) / per_log10
            if p > MIN_UNIGRAM_LOG10:
                out[w] = p
    return out


def _rival_distance(pron: Pron, other: Pron) -> int | None:
    """Phones ``other`` adds after ``pron`` (at most MAX_EXTRA_PHONES), or None.

    Shorter words are no rivals either: noise hiding one phone of a real trigger would
    let them win.
    """
    n, m = len(pron), len(other)
    if n < m <= n + MAX_EXTRA_PHONES and other[:n] == pron:
        return m - n
    return None


#: how many final phones a word shares with a trigger to count as ending like it
SHARED_ENDING_PHONES = 2


def commoner_words_ending_alike(word: str, prons: tuple[Pron, ...],
                                exclude: set[str]) -> list[str]:
    """Words more common than the trigger ``word`` (the bundled language model's unigram)
    with as many phones, the same last SHARED_ENDING_PHONES and more than half of its
    phones (as a multiset): "picture" and "culture" for "capture". The decoding tiers
    weigh them like confusable words.

    Operators and the people around them say such words far more often than the trigger,
    and in noise the recogniser took "picture" for "capture" (seeds 101-124 at 10 dB, 14
    of 41 false alarms). All words ending alike took real triggers ("record": 165 of
    them), and so did commoner ones made of other sounds: with "whatnot" competing,
    "snapshot" at sensitivity 1 lost 9 and 15 of its 205 triggers at 10 and 5 dB, with
    "york" "mark" lost 6 at 5 dB. A word the language model does not know (a user
    pronunciation) has none.
    Found / false alarms without -> with them: seeds 101-124 at 20 / 10 / 5 dB 970 / 5,
    957 / 41, 903 / 66 -> 969 / 2, 957 / 29, 902 / 57; seeds 125-148 973 / 9, 954 / 37,
    922 / 56 -> 973 / 6, 954 / 29, 922 / 53; seeds 1-3 the same.
    """
    return list(_commoner_ending_alike(word, tuple(sorted(prons)), tuple(sorted(exclude))))


@functools.lru_cache(maxsize=16)
def _commoner_ending_alike(word: str, prons: tuple[Pron, ...],
                           exclude: tuple[str, ...]) -> tuple[str, ...]:
    unigram = _unigram_log10()
    if word not in unigram:
        return ()
    return tuple(sorted({other for other, alts in load_dictionary().items()
                         if other not in exclude
                         and unigram.get(other, -math.inf) > unigram[word]
                         and any(_ends_alike(a, p) for a in alts for p in prons)}))


def _ends_alike(other: Pron, pron: Pron) -> bool:
    """Same length, same last SHARED_ENDING_PHONES, and more than half the phones shared."""
    shared = sum((Counter(other) & Counter(pron)).values())
    return len(other) == len(pron) and 2 * shared > len(pron) \
        and other[-SHARED_ENDING_PHONES:] == pron[-SHARED_ENDING_PHONES:]


#: a word this many orders of magnitude rarer than the trigger (the bundled language
#: model's unigram) is no confusable: people hardly say it, and where the recogniser
#: hears it, it mostly heard the trigger. "mark" heard as "marv" (2.3 rarer) kept the
#: similarity search from taking it (CONTESTED_SHARE of ``self_similarity``). Seeds
#: 101-104 at 20 dB, recall / precision: "mark" 0.530 / 0.978 -> 0.616 / 0.981, "record"
#: ("rickard", "checkered", ...) 0.780 / 0.962 -> 0.848 / 0.965; seeds 101-103, "mark"
#: at 10 dB 62 / 10 false -> 66 / 4, at 5 dB 47 / 11 -> 59 / 10, "record" the same;
#: the benchmark's seeds 1-3 at 20 / 10 / 5 dB, "mark" 0.43 / 1.00, 0.45 / 0.97, 0.50 /
#: 0.76 -> 0.53 / 1.00, 0.54 / 0.99, 0.61 / 0.93. "capture" keeps both of its own
#: ("captor" 1.9 rarer, "rapture" 1.2); real "clubs" loses "clubbed", same figures
MAX_RARER_LOG10 = 2.0


def confusable_words(word: str, prons: tuple[Pron, ...], exclude: set[str]) -> list[str]:
    """Common words one phone away from the trigger ``word``, same length ("rapture",
    "captor"), at most MAX_RARER_LOG10 rarer than it (where the language model knows it).

    Noisier speech weighs them at a smaller prior (the decoding tiers): in noise they win
    over real triggers too often. Looser neighbourhoods (shared opening or ending:
    "captain", "globe's" for "clubs") took real triggers from recorded human speech even
    at 25 dB; of the words ending alike only the commoner ones compete
    (:func:`commoner_words_ending_alike`).
    """
    return list(_confusables(word, tuple(sorted(prons)), tuple(sorted(exclude))))


@functools.lru_cache(maxsize=16)
def _confusables(word: str, prons: tuple[Pron, ...], exclude: tuple[str, ...]
                 ) -> tuple[str, ...]:
    unigram = _unigram_log10()  # its words are the common ones
    rarest = unigram[word] - MAX_RARER_LOG10 if word in unigram else -math.inf
    out = [other for other, alts in load_dictionary().items()
           if other not in exclude and other in unigram and unigram[other] >= rarest
           and any(len(a) == len(p) and sum(x != y for x, y in zip(a, p, strict=True)) == 1
                   for a in alts for p in prons)]
    return tuple(sorted(out)[:MAX_RIVALS])
