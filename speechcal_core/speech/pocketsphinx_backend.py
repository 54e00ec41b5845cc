"""Default backend: keyword-versus-filler decoding with pocketsphinx on voice-active spans.

Each speech span is decoded with one finite-state grammar in which the trigger words
compete with their rival words (inflections such as "captured", at a small prior: operators
say the trigger far more often) and, at a cost per phone, with a free phone loop that
absorbs everything else. A trigger is reported only where it explains the audio better
than all of those. How clearly a span is heard (its level above the noise floor) picks
the grammar's tier. Every tier weighs one-phone neighbours ("rapture", "captor") and
commoner words ending like the trigger ("picture") against it, noisier tiers at a smaller
prior (noise lets them win over real triggers).
A trigger's bounds come from the same Viterbi path, then move to the onset and offset of
the word's energy (recognised bounds run 30-40 ms early on reverberant speech); an
opening or closing fricative is measured in a band up to 7.5 kHz, where its hiss shows.
The sensitivity sets the phone-loop cost (a dearer filler lets more words pass) and how
close to the found triggers a span must sound to join them.
Finally the recording is searched for spans that sound like the triggers found (same
speaker, same word: see ``self_similarity``), which recovers words the recogniser lost
(in noise, or a trigger word it knows less well than "capture"); spans it heard as a
near-homophone need a much closer match. Spans it took for an inflection are searched
too: some voices say "capture" so that it hears "capturing"; such a span said on its own
is also searched with, as a template of that voice, and taken with the spans it finds
where it finds two or more. Before the search, the noisiest spans where the recogniser
heard nothing are decoded again more sensitively: a voice it hardly hears gets templates
there; so are the clearest such spans, much more sensitively: the filler's cost is tuned
on "capture", and other words said clearly go unheard at it. Where it hears too few
triggers for the search to start from (a short recording in loud noise), all the speech
is. Where the triggers are heard clearly, a find whose voiced sound unfolds unlike every
heard trigger's is dropped (``word_shape``: the search's DTW does not measure how long a
word's parts last, where "rapture" differs).
A trigger, recognised or found, whose sound runs on without a pause, or resumes after a
pause too short to end a phrase, is dropped: it is the start of something longer
("captured it?"). Operators say the trigger word on its own.
The spans are decoded in chunks, by worker processes where there are several cores, with
the same words however many decode them (``span_decoding``).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechError
from speechcal_core.speech.hiss_bounds import FRICATIVES, hiss_bounds
from speechcal_core.speech.lexicon import (
    PHONES,
    commoner_words_ending_alike,
    confusable_words,
    model_dir,
    pronunciations,
    rival_words,
)
from speechcal_core.speech.self_similarity import MIN_SEEDS, confirm_and_expand
from speechcal_core.speech.span_decoding import (
    RATE,
    WARM_UP_SEARCH,
    Chunk,
    Span,
    decode_chunk,
    decode_spans,
    default_workers,
)
from speechcal_core.speech.speech_index import Representation
from speechcal_core.speech.spot_grammar import (
    PEAK_PERCENTILE,
    TIERS,
    grammar_name,
    search_name,
    spot_grammar,
    tier_index,
    word_loop,
)
from speechcal_core.speech.timing import word_bounds
from speechcal_core.speech.vad import VoiceActivity, voice_activity
from speechcal_core.speech.word_shape import shaped_like

if TYPE_CHECKING:
    from speechcal_core.audio import Audio
    from speechcal_core.speech.matching import TriggerSpec

PHONE_PREFIX = "ph_"
WARM_UP_PHONE = "AH"  # the one phone a decoder warms up with (``span_decoding``)
#: narrow beams keep a phone loop fast; bestpath is off (its lattice costs seconds).
#: Front-end settings do not belong here: the model's ``feat.params`` (noise removal on,
#: batch CMN, its filter bank) overrides them when given to ``Decoder``. Only
#: ``decoder.config[...]`` followed by ``reinit_feat`` changes them, and the model's
#: noise removal is what lets it hear speech in room noise at all: without it the
#: recogniser alone heard 17 of 493 triggers at 5 dB (seeds 101-112), with it 226.
#: Filtering the room noise's low band out of the spans decoded (a 250 Hz high-pass) did
#: worse than leaving it to that noise removal: 5 dB, seeds 101-112, found / false alarms
#: 474 / 26 -> 467 / 29, the female voice's misses 16 -> 24. Nor does a frequency warp
#: (``warp_params``, inverse linear) reach that voice: with every span decoded at
#: sensitivity 0.7 and a warp of 1.2, her triggers heard rose from 55 to 70 of 246 (5 dB,
#: seeds 101-124) and the other voices' fell from 488 to 404; decoding with it the
#: noisiest spans still unheard after ``_listen_harder``, found / false alarms 937 / 51 ->
#: 936 / 52. Her missed triggers lie 3-12 dB above the floor, and in 41 of 42 nothing of
#: the vocabulary is heard there at sensitivity 0.5, 0.7 or 0.9, warped by 1, 1.2 or 1.35.
#: A Wiener-style noise suppression of the whole file ahead of everything (noise from each
#: STFT bin's 20th percentile, gain floor 0.15 or 0.4) did worse too: 474 / 26 -> 457 / 105
#: or 469 / 35; its residual "musical" noise is heard as words and matches the seeds.
DECODER_OPTIONS: dict[str, Any] = {
    "beam": 1e-30, "pbeam": 1e-30, "wbeam": 1e-20, "bestpath": False, "loglevel": "ERROR",
}


#: spans heard at least this clearly: their found triggers are checked (SEED_CHECK), and
#: the similarity search adds a word there only on a closer match (CLEAR_SHARE of
#: ``self_similarity``: the recogniser heard clearly and heard no trigger). It added none
#: there before, trusting the recogniser; but for words other than "capture" it misses
#: many clear ones. Seeds 1-3 at 20 dB, recall / false alarms: "snapshot" 0.576 / 25 ->
#: 0.663 / 25, "record" 0.624 / 11 -> 0.732 / 11, "mark" 0.385 / 0 -> 0.429 / 0;
#: "capture" the same on seeds 1-3 at 20, 10 and 5 dB, seeds 101-112 at 20 dB 483 -> 485
#: found (5 false alarms), seeds 101-124 at 10 dB 954 -> 956 (40 -> 41 false alarms)
CHECKED_FROM_DB = TIERS[0].min_level_db
#: similarity search adds words only where something stands out of the noise at all (not
#: in a span's quiet padding)
EXPAND_MIN_DB = 4.0
#: similarity expansion: accepted cost relative to the triggers' mutual cost, at 0 and 1,
#: for a span heard as clearly as the triggers (quieter spans get more: LEVEL_SLOPE)
SIMILARITY_FACTOR = (1.0, 1.2)
#: where the triggers the recogniser found are heard less than this above the noise floor
#: (their median), the search compares Gaussian posteriorgrams instead of MFCCs, with
#: their own factor: in that much noise they find more of a quiet voice, while in clearer
#: recordings MFCCs keep more near-homophones out. Found triggers lie 13-14 dB above the
#: floor in 5 dB sessions, 16-17.5 dB in 10 dB ones. 5 dB, recall / precision, MFCC ->
#: posteriorgram: seeds 1-3 0.849 / 0.951 -> 0.956 / 0.938; seeds 101-112 0.903 / 0.904
#: -> 0.903 / 0.918; seeds 113-124 0.862 / 0.891 -> 0.868 / 0.922. At 10 dB they were no
#: better (seeds 1-3: 0.995 / 0.971 -> 0.966 / 0.952)
POSTERIORGRAM_BELOW_DB = 15.0
POSTERIORGRAM_FACTOR = (1.2, 1.4)
#: how much more a quieter span may cost on posteriorgrams (``self_similarity``'s
#: LEVEL_SLOPE, 0.05, is the MFCCs'): a buried trigger's posteriorgram drifts further
#: from the templates per dB. 5 dB, 0.05 -> 0.06: seeds 1-3 198 / 5 false -> 200 / 5;
#: seeds 101-148 1802 / 109 -> 1825 / 122 (recall 0.917 -> 0.929, precision 0.943 ->
#: 0.937); 10 dB the same. 0.07 everywhere: 101-148 at 5 dB 1835 / 139, at 10 dB 1935 /
#: 105 (from 1910 / 77)
POSTERIORGRAM_LEVEL_SLOPE = 0.06
#: a found trigger in a clearly heard span whose closest other found trigger costs more
#: than this times their median closest cost is dropped (``confirm_and_expand``'s
#: ``verify``): near-homophones the recogniser took for the trigger rarely sound like the
#: operator's other triggers. Tuning seeds 101-112, 20 dB precision 0.955 -> 0.975,
#: recall 0.990 -> 0.987. Noisy seeds are not checked: on seeds 1-3 that dropped real
#: triggers and with them the templates that find others (5 dB recall 0.844 -> 0.800).
SEED_CHECK: float | None = 1.5
#: ... unless the recogniser still hears it with its filler at its cheapest (at
#: DOUBT_SENSITIVITY): there the near-homophones it took for the trigger
#: ("captain", "capsule", "rapture") go to the phone loop, while a voice's one trigger
#: stays the trigger. A voice that says the trigger once in a recording has no close
#: sibling among the others: 30 s sessions of seeds 101-160 at 20 dB (six triggers, four
#: voices) lost 67 of 360 triggers to the check, 66 of them heard clearly. Of the seeds it
#: dropped there and in 120 s sessions (seeds 101-149), the cheaper filler kept 56 of 62
#: triggers and 2 of 16 near-homophones (a filler phone at log10 -4 instead of -3: 60
#: triggers and 6 near-homophones). The cheapest whatever the sensitivity: at sensitivity
#: 1, a filler only 0.5 cheaper still heard "record" in a "recorder" the check had dropped
DOUBT_SENSITIVITY = 0.0
#: ... in the clearest tier's grammar with the inflections at the trigger's own prior
#: ("recorder" for "record": one voice's it heard as "record" at the cheapest filler
#: too). Found / false alarms at 20 dB, the 60 s sessions below: 195 / 5 -> 195 / 4, made
#: with one camera 190 / 5 -> 190 / 4; the 30 s ones the same
DOUBT_TIER = replace(TIERS[0], rival_log10=0.0)
#: the decoders' name of that grammar
DOUBT_SEARCH = "doubt"
#: ... and only where the recogniser heard fewer triggers than this: with more, every voice
#: has said it several times, and what the check drops is nearly always a near-homophone.
#: In 120 s sessions (about 40 heard) the cheaper filler kept those: seeds 125-148 at
#: 20 dB, found / false alarms 973 / 7 -> 974 / 14 (inflections at their usual prior).
#: Below 30, found / false alarms
#: before -> after: the 30 s sessions above 293 / 11 -> 353 / 13; ten 60 s sessions at
#: 20 dB (seeds 3, 9, 21, 31-37, about 19 triggers each) 192 / 3 -> 195 / 4, made with
#: one camera 184 / 4 -> 190 / 4 (below 20: 193 / 3 and 185 / 4); 120 s sessions at
#: 5 dB, seeds 101-124, 937 / 51 -> 937 / 53 (one session heard fewer), at 10 dB the same
DOUBT_BELOW_SEEDS = 30
#: how much more sensitively speech is decoded again (``_listen_harder``): the noisiest
#: spans where the recogniser heard nothing, and all of it where it hears too few
#: triggers for the similarity search to start from (fewer than its MIN_SEEDS of every
#: trigger word), as in a short recording in loud noise. For the latter, real speech
#: (``bench_real_speech``, four "clubs" a scene, 4 of 10 scenes at 5 dB had one or none
#: heard): 5 dB recall / precision 0.65 / 1.00 -> 0.975 / 1.00 (+0.3: 0.975 / 0.95).
#: Sessions of seeds 101-104 with every trigger replaced by room noise (near-homophones
#: left in), both together: 1 false alarm -> 2 at 20 dB, 0 -> 2 at 5 dB. +0.3 or +0.4:
#: 5 dB seeds 101-124 930 / 52 found / false -> 941 / 56, untouched 125-148 931 / 63 ->
#: 930 / 62. The recogniser is no judge of the similarity search's finds: decoded again at
#: sensitivity 0.9, a near-homophone heard there drops 6 true finds for 6 false (5 dB),
#: and at 5 dB its phone loop hears silence in most of them
RETRY_STEP = 0.2
#: how much more sensitively the clearest spans (the first tier's) where the recogniser
#: heard nothing are decoded again (``_listen_harder``): the filler's cost is tuned on
#: "capture", and other trigger words said clearly go unheard at it, a whole voice's at
#: times, which then has no template for the similarity search. Their triggers heard
#: there are checked against the others as every clear one is (SEED_CHECK). Seeds 1-3,
#: recall / precision at 20 dB: "snapshot" 0.693 / 0.840 -> 0.854 / 0.866, "record" 0.844
#: / 0.935 -> 0.956 / 0.942, "mark" 0.532 / 1.00 -> 0.707 / 1.00, "capture" 0.990 / 0.995
#: -> 0.995 / 0.986 (a "capsule" more); at 10 dB "snapshot" 0.463 / 0.792 -> 0.639 /
#: 0.834, "capture" the same; seeds 101-124, "capture" at 20 dB 0.985 / 0.998 -> 0.986 /
#: 0.998, at 10 dB 0.978 / 0.969 -> 0.979 / 0.969. Real speech (``bench_real_speech``,
#: "clubs") at 10 dB 0.95 / 1.00 -> 1.00 / 1.00, at 20 and 5 dB the same. A step of 0.5
#: found a little more of the other words ("snapshot" at 20 dB 0.868 / 0.864), but heard
#: "clubs" in a clearly said "five five" (twice, so the check let both pass as alike).
#: The second tier's spans too (at 0.5): "snapshot" at 10 dB 0.776 / 0.855, "record"
#: 0.522 / 0.892 -> 0.878 / 0.909, but "capture" at 10 dB 0.995 / 0.986 -> 1.000 / 0.962
#: and at 5 dB 0.980 / 0.971 -> 0.976 / 0.962 ("capsule", "rapture", alike to the
#: triggers: the check, made at every level for these, still let 5 of the 8 false alarms
#: pass at 10 dB, all at 5 dB). The whole benchmark takes 0.025-0.036 of real time;
#: "snapshot", with many more such spans at 20 dB, 0.053 -> 0.063 in CPU time
CLEAR_RETRY_STEP = 0.3
#: ... up to this sensitivity, no higher: from 0.8 (``--sensitivity 0.8``, the retry at 1)
#: real speech at 20 dB went from 1.00 / 1.00 to 1.00 / 0.78, "clubs" heard in "five"
CLEAR_RETRY_MAX = 0.8
#: a trigger word the filler's cost (tuned on "capture") lets pass too seldom shows it:
#: the middle tier's spans where nothing was heard, decoded again as the clearest are
#: (CLEAR_RETRY_STEP), hear many more of it. Their triggers are kept where they number at
#: least UNDERHEARD_SHARE of those heard before, and UNDERHEARD_MIN: the word needs the
#: dearer filler there too (real speech, four "clubs" a scene at 5 dB: where 2 more were
#: enough, 3 false alarms in 10 scenes, "clubs" heard in other words). Not otherwise: for
#: "capture" they are few (0-0.12 of those heard, seeds 101-104 at 10 and 5 dB), and as
#: templates they let the search take more near-homophones (10 dB, seeds 1-3: precision
#: 0.986 -> 0.962 when always kept). 10 dB, seeds 101-108, recall / precision: "record"
#: 0.378 / 0.899 -> 0.722 / 0.926, "mark" 0.438 / 0.960 -> 0.689 / 0.970, "snapshot"
#: 0.529 / 0.858 -> 0.725 / 0.833 (more "snap shut"); "capture" kept none at 10 dB (seeds
#: 101-112) and some in one session at 5 dB (5 of 19 more: the search had found them
#: already); its benchmark the same
UNDERHEARD_SHARE = 0.25
UNDERHEARD_MIN = 4
#: every this many of those spans are decoded first; the rest only where those heard at
#: least their share of what UNDERHEARD_SHARE and UNDERHEARD_MIN need. For "capture" the
#: retry hears 0-15 % more and keeps none, and decoding all those spans cost it a sixth
#: more CPU time (seeds 1-3, 10 dB, in one process: 0.0428 -> 0.0501 of real time); with
#: every second span first it stopped there in all six sessions at 10 and 5 dB. 10 dB,
#: seeds 101-108, recall / precision, all spans -> every second first (every third):
#: "record" 0.722 / 0.926 -> 0.758 / 0.930 (0.631 / 0.937), "mark" 0.689 / 0.970 ->
#: 0.650 / 0.977 (0.601 / 0.966). The benchmark's seeds 1-3, before any of this -> now,
#: 10 / 5 dB: "record" 0.56 -> 0.80 / 0.41 -> 0.48, "mark" 0.55 -> 0.77 / 0.61 -> 0.68,
#: "snapshot" 0.64 -> 0.72 / 0.44 -> 0.38 (the words added as templates lost it some)
UNDERHEARD_SAMPLE = 2
DECODING_SHARE = 0.8  # of the work, for progress reports: the search takes the rest
#: the share of the work done once the more sensitive decodings are done
LISTENING_HARDER_SHARE = DECODING_SHARE + (1.0 - DECODING_SHARE) / 2


@dataclass
class Heard:
    """What one decoding pass heard: the words (bounds snapped to their energy), the
    triggers running on into more speech, and the recogniser's own end of each word
    closing in a hiss."""

    words: list[Word] = field(default_factory=list)
    running_on: list[Word] = field(default_factory=list)
    heard_ends: dict[Word, float] = field(default_factory=dict)
    #: the words of ``words`` followed by a pause (not the start of something longer)
    alone: set[Word] = field(default_factory=set)

    def triggers(self, spec: TriggerSpec) -> list[Word]:
        """The trigger words heard (not those running on)."""
        return [w for w in self.words if w.word in spec.words]

    def with_triggers(self, other: Heard, spec: TriggerSpec) -> Heard:
        """These words and ``other``'s triggers, in time order."""
        added = other.triggers(spec)
        return Heard(sorted(self.words + added, key=lambda w: w.start_s), self.running_on,
                     {**self.heard_ends,
                      **{w: end for w, end in other.heard_ends.items() if w in added}},
                     self.alone | (other.alone & set(added)))


def _too_few_to_search(triggers: list[Word]) -> bool:
    """Whether no trigger word was heard often enough to search for more like it."""
    return all(n < MIN_SEEDS for n in Counter(w.word for w in triggers).values())


def underheard_words(words: tuple[str, ...], before: Mapping[str, int],
                     added: Mapping[str, int]) -> tuple[str, ...]:
    """The trigger ``words`` a keener decoding heard many more times (``added``) than
    the decodings ``before`` it (UNDERHEARD_SHARE, UNDERHEARD_MIN): the filler lets them
    pass too seldom."""
    return tuple(word for word in words if added.get(word, 0) >= max(
        UNDERHEARD_MIN, UNDERHEARD_SHARE * before.get(word, 0)))


def _keener(spec: TriggerSpec) -> TriggerSpec:
    """``spec`` as unheard spans are decoded again: CLEAR_RETRY_STEP more sensitive, up
    to CLEAR_RETRY_MAX (at or above that, no keener than ``spec``: no retry)."""
    return replace(spec, sensitivity=min(CLEAR_RETRY_MAX, spec.sensitivity + CLEAR_RETRY_STEP))


def _retry_note(before: list[Word], spec: TriggerSpec, louder: TriggerSpec,
                heard_again: int) -> str:
    """What the operator is told when the speech was decoded again more sensitively."""
    heard = {0: "no trigger word", 1: "only one trigger word"}.get(
        len(before), f"only {len(before)} trigger words")
    return (f"the recogniser heard {heard} at sensitivity {spec.sensitivity:g}, too few "
            f"to search for others that sound alike, so it listened again at "
            f"{louder.sensitivity:g} and heard {heard_again}")


class PocketsphinxBackend:
    """Trigger words from pocketsphinx's bundled English model; CPU only, no download."""

    name = "pocketsphinx"

    def __init__(self, expand: bool = True,
                 progress: Callable[[float], None] | None = None,
                 workers: int | None = None) -> None:
        self.expand = expand
        #: processes decoding at once (None: ``span_decoding.default_workers``); the
        #: result does not depend on it
        self.workers = default_workers() if workers is None else workers
        #: CPU seconds the worker processes spent on the last call (this process's own
        #: are in ``time.process_time``)
        self.last_worker_cpu_s = 0.0
        #: called with the share of the work done (0..1: decoding the speech up to
        #: DECODING_SHARE, then the similarity search); it may raise to stop
        self.progress = progress
        self.last_activity: VoiceActivity | None = None  # of the last call, for reports
        #: set when the recogniser was asked again at a higher sensitivity (RETRY_STEP)
        self.last_note: str | None = None
        self._decoder: Any = None
        self._key: tuple | None = None
        self._sensitivities: set[float] = set()  # those the decoder has grammars for
        self._phones: list[str] = []
        self._vocab: set[str] = set()
        #: the trigger words' inflections and near-homophones, in the grammar's order
        self._rivals: list[str] = []
        self._confusables: list[str] = []
        self._hiss_first: set[str] = set()  # triggers opening with a fricative
        self._hiss_last: set[str] = set()  # triggers closing with one

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        """Trigger words and rival words found in ``audio``, in time order."""
        x = audio.resampled(RATE).samples if audio.rate != RATE else audio.samples
        activity = voice_activity(x, RATE)
        self.last_activity = activity
        self.last_note = None
        self.last_worker_cpu_s = 0.0
        heard = self._hear(x, activity, activity.segments, spec, (0.0, DECODING_SHARE))
        share = DECODING_SHARE  # of the work done once the speech is decoded
        if self.expand and activity.segments and spec.sensitivity < 1.0:
            heard, spec = self._listen_harder(x, activity, spec, heard)
            share = LISTENING_HARDER_SHARE
        refined, running_on, heard_ends = heard.words, heard.running_on, heard.heard_ends
        if not self.expand:
            return self._hiss_bounds(x, activity, refined, heard_ends)
        if self.progress is not None:
            self.progress(share)
        out = [w for w in refined if w.word not in spec.words]
        for trigger in spec.words:
            seeds = [w for w in refined if w.word == trigger]
            # rivals (inflections) do not keep the search out: some voices say "capture"
            # so the recogniser hears "capturing", and the search recovers those; where it
            # heard a near-homophone ("rapture") the search needs a much closer match
            others = [w for w in refined if w.word != trigger and w.word not in self._rivals
                      and w.word not in self._confusables]
            others += running_on
            contested = [w for w in refined if w.word in self._confusables]
            inflected = [w for w in refined if w.word in self._rivals and w in heard.alone]
            levels = [activity.level_db(w.start_s, w.end_s) for w in seeds]
            search, (lo, hi), slope = _search_for(levels)
            clear = [level >= CHECKED_FROM_DB for level in levels]
            kept, extra = confirm_and_expand(x, RATE, seeds, activity, others,
                                             lo + (hi - lo) * spec.sensitivity,
                                             verify=SEED_CHECK, checked=clear, search=search,
                                             contested=contested, level_slope=slope,
                                             clear_from_db=CHECKED_FROM_DB,
                                             inflected=inflected,
                                             second_opinion=self._second_opinion(
                                                 x, activity, spec, len(seeds)))
            extra = [w for w in extra if activity.level_db(w.start_s, w.end_s) >= EXPAND_MIN_DB]
            # finds shaped unlike every heard trigger go ("rapture": voiced from its start).
            # Only where the triggers are heard clearly enough for MFCCs: 10 dB, found /
            # false alarms, seeds 101-124 963 / 31 -> 962 / 17, untouched 125-148 957 / 29
            # -> 957 / 17; 20 dB the same. In 5 dB noise the shapes blur: 937 / 51 ->
            # 921 / 26 on seeds 101-124 (limit 0.16), a trigger lost for every other
            # false alarm
            if search == "mfcc":
                extra = shaped_like(x, RATE, kept, extra)
            out += kept + extra
        triggers = [w for w in out if w.word in spec.words]
        neighbours = {*self._rivals, *self._confusables}
        out = [w for w in out if w.word not in neighbours
               or not any(t.start_s < w.end_s and w.start_s < t.end_s for t in triggers)]
        return sorted(self._hiss_bounds(x, activity, out, heard_ends), key=lambda w: w.start_s)

    def _listen_harder(self, x: np.ndarray, activity: VoiceActivity, spec: TriggerSpec,
                       heard: Heard) -> tuple[Heard, TriggerSpec]:
        """``heard`` with the triggers of a more sensitive decoding (RETRY_STEP) of the
        noisiest spans where nothing was heard, and of a much more sensitive one
        (CLEAR_RETRY_STEP) of the clearest such spans; and where the recogniser still
        hears too few triggers to search from, all of a more sensitive decoding instead,
        with the spec it was made at (``last_note`` says so).

        The noisiest spans' filler is dear already, but dearer still it lets pass the
        triggers of a voice the recogniser hardly hears, which then serve the search as
        templates of that voice; only where it heard nothing, so that a near-homophone
        it heard stays one. 5 dB, recall / precision: seeds 101-124 0.917 / 0.941 ->
        0.945 / 0.947, untouched seeds 125-148 0.940 / 0.946 -> 0.949 / 0.937; 10 dB,
        seeds 101-124 0.973 / 0.971 -> 0.978 / 0.969; the benchmark's seeds 1-3 at 5 dB
        0.976 / 0.976 -> 0.980 / 0.971, at 10 dB 0.995 / 0.990 -> 0.995 / 0.986. About a
        sixth more CPU at 5 dB. Checking the added triggers against the others
        (SEED_CHECK) lost 13 of them on seeds 113-124 for one false alarm fewer on 137-148.
        """
        louder = replace(spec, sensitivity=min(1.0, spec.sensitivity + RETRY_STEP))
        middle = (DECODING_SHARE + LISTENING_HARDER_SHARE) / 2
        quarter = (DECODING_SHARE + middle) / 2
        at_first = heard.triggers(spec)  # at spec's own sensitivity, for the note
        eighth = (DECODING_SHARE + quarter) / 2
        heard = self._hear_clear_again(x, activity, spec, heard, (DECODING_SHARE, eighth))
        heard = self._hear_middle_again(x, activity, spec, heard, (eighth, quarter))
        unheard = _unheard_spans(activity, heard, len(TIERS) - 1)  # the noisiest
        more = self._hear(x, activity, unheard, louder, (quarter, middle))
        heard = heard.with_triggers(more, spec)
        if _too_few_to_search(heard.triggers(spec)):
            again = self._hear(x, activity, activity.segments, louder,
                               (middle, LISTENING_HARDER_SHARE))
            if len(again.triggers(louder)) > len(heard.triggers(spec)):
                self.last_note = _retry_note(at_first, spec, louder,
                                             len(again.triggers(louder)))
                return again, louder
        return heard, spec

    def _hear_clear_again(self, x: np.ndarray, activity: VoiceActivity, spec: TriggerSpec,
                          heard: Heard, shares: tuple[float, float]) -> Heard:
        """``heard`` with the triggers of a much more sensitive decoding
        (CLEAR_RETRY_STEP, up to CLEAR_RETRY_MAX) of the clearest spans where nothing was
        heard."""
        keen = _keener(spec)
        if keen.sensitivity <= spec.sensitivity:
            return heard
        clearest = _unheard_spans(activity, heard, 0)
        return heard.with_triggers(self._hear(x, activity, clearest, keen, shares), spec)

    def _hear_middle_again(self, x: np.ndarray, activity: VoiceActivity,
                           spec: TriggerSpec, heard: Heard, shares: tuple[float, float]
                           ) -> Heard:
        """``heard`` with the triggers of a decoding as sensitive as
        :meth:`_hear_clear_again`'s of the middle tier's spans where nothing was heard,
        for each trigger word of which it hears many more (UNDERHEARD_SHARE). Every
        UNDERHEARD_SAMPLE-th span is decoded first, the rest only where that heard its
        share of what a word needs (:func:`underheard_words`)."""
        keen = _keener(spec)
        middle = _unheard_spans(activity, heard, 1)
        if keen.sensitivity <= spec.sensitivity or not middle:
            return heard
        before = Counter(w.word for w in heard.triggers(spec))
        half_way = (shares[0] + shares[1]) / 2
        sample = self._hear(x, activity, middle[::UNDERHEARD_SAMPLE], keen,
                            (shares[0], half_way))
        added = Counter(w.word for w in sample.triggers(spec))
        if not underheard_words(spec.words, before,  # the sample's share of what is needed
                                {w: n * UNDERHEARD_SAMPLE for w, n in added.items()}):
            return heard
        rest = [span for k, span in enumerate(middle) if k % UNDERHEARD_SAMPLE]
        more = self._hear(x, activity, rest, keen, (half_way, shares[1]))
        added += Counter(w.word for w in more.triggers(spec))
        underheard = underheard_words(spec.words, before, added)
        if not underheard:
            return heard
        kept = replace(spec, words=underheard)
        return heard.with_triggers(sample, kept).with_triggers(more, kept)

    def _second_opinion(self, x: np.ndarray, activity: VoiceActivity, spec: TriggerSpec,
                        seeds: int) -> Callable[[list[Word]], list[Word]] | None:
        """What the seed check asks about the triggers it would drop, where fewer than
        DOUBT_BELOW_SEEDS were heard (``seeds``) and ``spec`` is more sensitive than
        DOUBT_SENSITIVITY: those still heard with the cheapest filler (:meth:`_still_heard`)
        are kept."""
        if seeds >= DOUBT_BELOW_SEEDS or spec.sensitivity <= DOUBT_SENSITIVITY:
            return None
        return lambda doubted: self._still_heard(x, activity, spec, doubted)

    def _still_heard(self, x: np.ndarray, activity: VoiceActivity, spec: TriggerSpec,
                     triggers: list[Word]) -> list[Word]:
        """Those of ``triggers`` the recogniser still hears with its filler at its
        cheapest (DOUBT_SEARCH). Each one's span is decoded here, after the span before it
        as the front end's warm-up."""
        kept = []
        for trigger in triggers:
            k = next((k for k, (a, b) in enumerate(activity.segments) if a <= trigger.t <= b),
                     None)
            if k is None:
                continue
            warm_up = _samples(x, activity.segments[k - 1]) if k else None
            span = Span(activity.segments[k][0], _samples(x, activity.segments[k]),
                        DOUBT_SEARCH)
            heard = self.decode_chunk(spec, Chunk(warm_up, [span]))
            if any(w.word == trigger.word and w.start_s < trigger.end_s
                   and trigger.start_s < w.end_s for w in heard):
                kept.append(trigger)
        return kept

    def _hear(self, x: np.ndarray, activity: VoiceActivity,
              segments: list[tuple[float, float]], spec: TriggerSpec,
              shares: tuple[float, float]) -> Heard:
        """What the recogniser hears in ``segments`` (voice-active spans of ``x``) at
        ``spec``'s sensitivity, word bounds snapped to the words' energy; progress is
        reported from ``shares[0]`` to ``shares[1]`` of the work."""
        self._prepare(spec)  # for the word lists below
        spans = [Span(start, _samples(x, (start, end)), search_name(
                     spec.sensitivity, activity.level_db(start, end),
                     activity.level_db(start, end, PEAK_PERCENTILE)))
                 for start, end in segments]
        found, worker_cpu_s = decode_spans(
            spans, spec, lambda chunk: self.decode_chunk(spec, chunk), self.workers,
            lambda done: self._report(shares, done))
        self.last_worker_cpu_s += worker_cpu_s
        heard = Heard()
        for w in _dedupe(found):
            bounds = word_bounds(x, RATE, w.start_s, w.end_s, activity.floor_at(w.t))
            word = Word(w.word, bounds.start_s, bounds.end_s, w.score, w.source)
            if w.word in self._hiss_last:
                heard.heard_ends[word] = w.end_s
            # a trigger whose sound runs on without a pause is the start of something
            # longer ("captured it?"): not reported, and no template for the search below
            running_on = bounds.runs_on and w.word in spec.words
            (heard.running_on if running_on else heard.words).append(word)
            if not bounds.runs_on:
                heard.alone.add(word)
        return heard

    def decode_chunk(self, spec: TriggerSpec, chunk: Chunk) -> list[Word]:
        """The words of ``spec``'s grammars (triggers, rivals, confusables) in one chunk
        of spans, decoded in this process."""
        return decode_chunk(self._prepare(spec), chunk, self._vocab)

    def _report(self, shares: tuple[float, float], fraction: float) -> None:
        """Progress at ``fraction`` of the way from ``shares[0]`` to ``shares[1]``."""
        if self.progress is not None:
            self.progress(shares[0] + (shares[1] - shares[0]) * fraction)

    def _hiss_bounds(self, x: np.ndarray, activity: VoiceActivity, words: list[Word],
                     heard_ends: dict[Word, float]) -> list[Word]:
        """``words`` with the trigger words' hisses in their bounds (:func:`hiss_bounds`)."""
        return hiss_bounds(x, activity, words, heard_ends, self._hiss_first, self._hiss_last)

    def _prepare(self, spec: TriggerSpec) -> Any:
        """One decoder per trigger configuration, reused for every span; its grammars
        (one per tier) are added per sensitivity as needed."""
        key = (spec.words, tuple(sorted(spec.pronunciations.items())))
        if self._decoder is None or key != self._key:
            self._decoder = self._new_decoder(spec)
            # one phone: whatever the warm-up decodes, the front end adapts, cheaply
            self._decoder.add_fsg(WARM_UP_SEARCH, word_loop(
                self._decoder.get_logmath(), WARM_UP_SEARCH,
                [(PHONE_PREFIX + WARM_UP_PHONE.lower(), 0)]))
            self._decoder.add_fsg(DOUBT_SEARCH, spot_grammar(
                self._decoder.get_logmath(), replace(spec, sensitivity=DOUBT_SENSITIVITY),
                self._rivals, self._confusables, self._phones, DOUBT_TIER))
            self._key = key
            self._sensitivities = set()
        if spec.sensitivity not in self._sensitivities:
            logmath = self._decoder.get_logmath()
            for k, tier in enumerate(TIERS):
                grammar = spot_grammar(logmath, spec, self._rivals, self._confusables,
                                        self._phones, tier)
                self._decoder.add_fsg(grammar_name(spec.sensitivity, k), grammar)
            self._sensitivities.add(spec.sensitivity)
        return self._decoder

    def _new_decoder(self, spec: TriggerSpec) -> Any:
        """A decoder knowing ``spec``'s words, their rivals, confusables and the phones."""
        import pocketsphinx

        mdir = model_dir()
        decoder = pocketsphinx.Decoder(hmm=str(mdir / "en-us"),
                                       dict=str(mdir / "cmudict-en-us.dict"), lm=None,
                                       **DECODER_OPTIONS)
        user = dict(spec.pronunciations)
        rivals: list[str] = []
        confusables: list[str] = []
        hiss_first: set[str] = set()
        hiss_last: set[str] = set()
        for w in spec.words:
            prons = pronunciations(w, user)
            if any(p[0] in FRICATIVES for p in prons):
                hiss_first.add(w)
            if any(p[-1] in FRICATIVES for p in prons):
                hiss_last.add(w)
            if decoder.lookup_word(w) is None:
                _add_word(decoder, w, prons[0])
            elif w in user:
                known, free = _alternates(decoder, w)
                if prons[0] not in known:
                    _add_word(decoder, free, prons[0])  # an accent
            rivals += [r for r in rival_words(prons, set(spec.words)) if r not in rivals]
            alike = confusable_words(w, prons, set(spec.words)) \
                + commoner_words_ending_alike(w, prons, set(spec.words))
            confusables += [r for r in alike if r not in rivals and r not in confusables]
        for p in sorted(PHONES):
            _add_word(decoder, PHONE_PREFIX + p.lower(), (p,))
        self._phones = [PHONE_PREFIX + p.lower() for p in sorted(PHONES)]
        self._vocab = set(spec.words) | set(rivals) | set(confusables)
        self._rivals, self._confusables = rivals, confusables
        self._hiss_first, self._hiss_last = hiss_first, hiss_last
        return decoder


def _samples(x: np.ndarray, segment: tuple[float, float]) -> np.ndarray:
    """The samples of ``x`` from ``segment[0]`` to ``segment[1]`` (seconds)."""
    return x[int(segment[0] * RATE):int(segment[1] * RATE)]


def _unheard_spans(activity: VoiceActivity, heard: Heard, tier: int
                   ) -> list[tuple[float, float]]:
    """The voice-active spans of ``tier`` where ``heard`` holds no word (running on or
    not)."""
    words = heard.words + heard.running_on
    return [(a, b) for a, b in activity.segments
            if tier_index(activity.level_db(a, b),
                           activity.level_db(a, b, PEAK_PERCENTILE)) == tier
            and not any(w.start_s < b and a < w.end_s for w in words)]


def _search_for(seed_levels: list[float]
                ) -> tuple[Representation, tuple[float, float], float | None]:
    """How the similarity search compares frames, its factor at sensitivity 0 and 1, and
    its level slope (None: ``self_similarity``'s) for triggers found at ``seed_levels`` dB
    above the noise floor."""
    if seed_levels and float(np.median(seed_levels)) < POSTERIORGRAM_BELOW_DB:
        return "posteriorgram", POSTERIORGRAM_FACTOR, POSTERIORGRAM_LEVEL_SLOPE
    return "mfcc", SIMILARITY_FACTOR, None


def _alternates(decoder: Any, word: str) -> tuple[set[tuple[str, ...]], str]:
    """The pronunciations the decoder holds for ``word`` (``word``, ``word(2)``, ...) and
    its first unused alternate entry: pocketsphinx refuses to redefine a word, and the
    search matches every alternate of a word in its grammar."""
    out, n, entry = set(), 1, word
    while (phones := decoder.lookup_word(entry)) is not None:
        out.add(tuple(phones.split()))
        n += 1
        entry = f"{word}({n})"
    return out, entry


def _add_word(decoder: Any, word: str, phones: tuple[str, ...]) -> None:
    try:
        decoder.add_word(word, " ".join(phones), True)
    except RuntimeError as exc:
        raise SpeechError(
            f"pocketsphinx refused the pronunciation {' '.join(phones)!r} of {word!r}; "
            f"check the phones"
        ) from exc


def _dedupe(words: list[Word]) -> list[Word]:
    """Drop repeats from overlapping pieces: the same word overlapping in time."""
    out: list[Word] = []
    for w in sorted(words, key=lambda w: w.start_s):
        if out and out[-1].word == w.word and w.start_s < out[-1].end_s:
            continue
        out.append(w)
    return out
