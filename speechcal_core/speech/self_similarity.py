"""Find more instances of a trigger by how much they sound like the ones already found.

An operator repeats the trigger word in one voice, so the instances the recogniser is
sure of serve as templates (query by example without a mark): spans that match a template
about as well as the templates match each other are triggers too. This recovers words the
recogniser loses in noise, where a same-speaker comparison still holds. Noise raises
the cost of a true match, so a span heard less clearly than the templates may cost more.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Sequence

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.features import HOP_S
from speechcal_core.speech.query_by_example import subsequence_dtw
from speechcal_core.speech.speech_index import NOISE_FLOOR, Representation, SpeechIndex
from speechcal_core.speech.timing import word_bounds
from speechcal_core.speech.vad import VoiceActivity

#: a span is accepted when its cost is below this times the seeds' typical mutual cost
COST_FACTOR = 1.1
MIN_SEEDS = 2
SEED_END_TOLERANCE = 10  # frames: where another seed's match may end
MAX_STRETCH = 1.6  # a match may be at most this much longer than its template
#: ... and at least this share of it: vertical DTW steps squeeze a template (a 0.42 s
#: "capture" matched 0.09 s of a door's echo). At 5 dB (seeds 101-124) the search's true
#: finds lie at 0.55-1.6 times their template, 12 of 392 below 1 / MAX_STRETCH
MIN_SQUEEZE = 0.5
#: searches; >1 makes found instances templates too (little gain, more false: 5 dB,
#: seeds 101-124, found / false alarms 930 / 52 -> 939 / 87)
ROUNDS = 1
#: seeds whose closest sibling costs more than this times the median closest cost are dropped
VERIFY_FACTOR = 1.7  # the backend sets its own (SEED_CHECK there)
#: fewer seeds give no reliable median: all are kept. At 4, real speech ("clubs" in
#: ``../shared/speech-real``, four a scene) lost one in 2 of 10 scenes at 20 dB; the
#: synthetic sessions (many more seeds) are the same at 6
VERIFY_MIN_SEEDS = 6
#: seeds whose typical closest cost is above this do not sound alike (different voices,
#: each heard once, as in a short recording): no check of the seeds and no search.
#: Sessions lie at 0.19-0.34 ("capture", seeds 1-3 and 101-124 at 20, 10 and 5 dB; MFCC
#: or posteriorgram), up to 0.36 for "snapshot" and "record"; a 12 s session with one
#: trigger each from two voices at 0.61 found two false ones, and four voices saying
#: "capture" once each lie at 0.42: the check dropped the one female voice's trigger, as
#: furthest from the rest, and the search took a "captain". The margin below is thin:
#: "mark" at 5 dB (seed 2) has two seeds at 0.401, whose search finds 56 of its triggers
#: (0.40 took "mark" at 5 dB from 103 found / 33 false to 47 / 4)
MAX_MUTUAL_COST = 0.41
#: a span heard less clearly than the seeds costs more even when it is the same word: the
#: limit grows by this fraction of the seeds' mutual cost per dB the span's level lies
#: below the seeds' median level (and shrinks for louder spans), within MAX_LEVEL_GAP_DB
LEVEL_SLOPE = 0.05
MAX_LEVEL_GAP_DB = 10.0
#: a span the recogniser heard as another word close to the trigger ("rapture" for
#: "capture") is taken only below this share of its limit: the operator's triggers must
#: sound much more alike than the near-homophone usually does. Seeds 1-3 and 101-112 at
#: 5 and 10 dB: the one real trigger heard as "rapture" lay at 0.47 of its limit, the 8
#: real raptures the search would take at 0.77-1.0
CONTESTED_SHARE = 0.6
#: a span heard at least ``clear_from_db`` above the noise floor (where the recogniser
#: heard no trigger although it heard clearly) is taken only below this share of its
#: limit. Seeds 1-3 at 20 dB, the whole limit there -> this share: "snapshot" 154 / 28
#: false -> 136 / 25, "record" 179 / 17 -> 150 / 11, "mark" 100 / 3 -> 88 / 0 (none found
#: there before: 118 / 25, 128 / 11, 79 / 0); "capture" 203 / 1 either way, seeds
#: 101-112 488 / 5 -> 485 / 5. A clean scene's "captain" lay at 0.88 of its limit
CLEAR_SHARE = 0.8
#: ... unless the template it matches has a far closest sibling: a voice whose instances
#: lie further apart (or whose fewer instances were found) has its matches there measured
#: against up to this times CLEAR_SHARE of the limit, in proportion to how much more the
#: template's closest sibling costs than the seeds' median. Seeds 1-3 at 20 dB, recall /
#: false alarms: "record" 0.73 / 11 -> 0.80 / 12, "snapshot" 0.66 / 25 -> 0.69 / 27,
#: "mark" 0.43 / 0 -> 0.43 / 0 (at 10 dB "record" 0.51 -> 0.52, the rest within a word);
#: "capture" the same on seeds 1-3, seeds 101-148 at 20 dB 1938 / 13 -> 1942 / 14, at
#: 10 dB 1910 / 77 -> 1911 / 78. 1.5: "record" 0.82 / 12, "snapshot" 0.69 / 27
CLEAR_VOICE_BOOST = 1.3
#: a span heard as an inflection of the trigger ("captured"), said on its own, is taken
#: with the spans it matches below the limit where it matches at least this many. A voice
#: the recogniser hears so has no seed, and its triggers match the other voices' seeds at
#: 1.2-1.6 times the limit, but each other much closer. One such span alone is no
#: trigger: an operator may say "captured". Every one of them taken: found / false alarms
#: at 5 dB on seeds 101-124 930 / 51 -> 943 / 55 ("captured it?" and "captain" heard as
#: "captured"). Taken with one find: 939 / 51 there, 926 / 63 -> 930 / 63 on untouched
#: seeds 125-148, but the benchmark's 10 dB sessions had 3 -> 5 false alarms, a "captain"
#: heard as "captured" finding another. With two: 937 / 51, 930 / 63, and the
#: benchmark's sessions as before at 5, 10 and 20 dB
FOUND_THROUGH_INFLECTION = 2
# Tried and left out. At 5 dB the near-homophones the search takes ("rapture", "capsule")
# match the same voice's triggers at 0.6-1.0 of their limit, as the true ones do, and no
# measure tried told them apart: the cost along the first third of the matched seed
# against that seed's matches of its siblings (or along its last or worst third: the
# false finds' lay lower than the true ones' on every third), how closely the second to
# fifth closest seeds match, MFCC and posteriorgram costs combined (5 dB, seeds
# 101-124: at best 8 false alarms fewer for 4 triggers lost), per-seed limits from each
# seed's closest sibling, a template averaged over a voice's seeds (aligned by DTW).
# Spans just over the limit that sound alike among themselves (a voice with no seed) gave
# 4 of the 54 missed triggers. Posteriorgram mixtures trained only on frames well above the noise
# floor moved along the same trade-off, below it (8 dB: 957 / 190, at a stricter limit
# 907 / 93). Seeds also read as said by a vocal tract 6-12 % shorter or longer (eight
# seeds most unlike each other, 5 % dearer) found more of a voice with few seeds, mostly
# through that voice's own seeds: 5 dB 930 / 52 -> 941 / 56 found / false alarms on
# seeds 101-124, 931 / 63 -> 939 / 70 on untouched 125-148, at 10 dB one to three found
# and one false alarm more; but a quarter more CPU, and on the benchmark's 5 dB sessions
# one false alarm more (precision 0.971 -> 0.966). Spans up to 1.5 times their limit
# that sound alike among themselves, decoded again (sensitivity 0.9, 0.3 s around them),
# gave a voice with no seed its own where two or more were heard as the trigger and
# matched each other, and those searched at the first search's limit: 5 dB 930 / 52 ->
# 944 / 54 on seeds 101-124, 931 / 63 -> 933 / 63 on 125-148, 10 dB and the benchmark
# the same, for a sixth more CPU. Most of such a voice's missed triggers are not heard
# as the trigger even at sensitivity 1 (session 125: 1 of 10). A forced choice over each
# found span (0.1 s around it) between the trigger and its rivals and confusables, with
# no phone loop, scored by the better path: at 5 dB (seeds 101-112) half of the
# search's finds got no path within the decoder's beams, and among the rest, dropping
# those where a neighbour scored better took 2 of 8 false alarms and 4 of 112 triggers.
# The spans the recogniser heard as a near-homophone, as counter-templates (a find
# dropped where one matches it closer than its seed does): at 5 dB (seeds 101-124) a
# session holds about one, 170 of 392 true finds and 13 of 28 raptures had none to
# compare with, and the rest overlap (cost over the seed's, 5th percentile: triggers
# 1.26, raptures 1.02); at a ratio of 1.1 it dropped 6 triggers and no false alarm.
# At 5 dB (seeds 101-124) 49 of the 54 missed triggers are one quiet female voice's,
# mostly in sessions where the recogniser heard none of hers: her triggers match the
# other voices' seeds at 1.2-1.6 times the limit but each other at 0.29-0.44 (seeds'
# mutual cost 0.26), closer than anything else. Taking spans within 1.6 times the limit
# that have three or four such spans within 1.3-1.4 times the mutual cost found 6-11 of
# the 54 for 0-2 false alarms; a single-linkage grouping chained into other words (+33
# triggers for +65 false). Normalising each voice's frames on their own (MFCC mean and
# variance per voice, from the true labels: the best any speaker clustering could do)
# left her triggers as far from the seeds (1.21-1.52 times the limit, none found).
# The backend drops finds whose shape in time (``word_shape``) is unlike every seed's, but
# not at 5 dB, where the search compares posteriorgrams: there, at a limit of 0.16, seeds
# 101-124 found / false alarms 937 / 51 -> 921 / 26, the benchmark's sessions 201 / 6 ->
# 199 / 4, and untouched 125-148 930 / 63 -> 917 / 42 (counted on the finds). Precision
# for recall, and a missed trigger costs the operator a view while a false one costs a
# click in review. At 0.2: 5 / 9 and 3 / 11 fewer; at 0.16 only for finds costing over
# 1.1 times the session's median find: 9 / 15 and 8 / 15 (counted on the finds).
# Searching 1.2 times wider before that check took more "capsule" and "captain" (their
# shapes are the trigger's): 943 / 64.
# Spans 1.0-1.3 times over the limit that match each other (her missed triggers: 27 of
# 42 lie there, at 1.01-1.15) also hold near-homophones that do: two or more such within
# 1.4 times the mutual cost, 3 triggers for 1 false alarm; within 1.6, 9 for 8.


def expand_by_similarity(samples: np.ndarray, rate: int, seeds: list[Word],
                         activity: VoiceActivity, blocked: list[Word],
                         factor: float = COST_FACTOR, rounds: int = ROUNDS,
                         level_slope: float = 0.0, search: Representation = "mfcc"
                         ) -> list[Word]:
    """New trigger instances similar to ``seeds``; nothing overlapping seeds or ``blocked``.

    The acceptance limit comes from the seeds alone; instances found in one round serve
    as further templates in the next. Every seed is kept as a template (no verification).
    """
    return confirm_and_expand(samples, rate, seeds, activity, blocked, factor, rounds,
                              verify=None, level_slope=level_slope, search=search)[1]


def confirm_and_expand(samples: np.ndarray, rate: int, seeds: list[Word],
                       activity: VoiceActivity, blocked: list[Word],
                       factor: float = COST_FACTOR, rounds: int = ROUNDS,
                       verify: float | None = VERIFY_FACTOR, noise_floor: float = NOISE_FLOOR,
                       checked: Sequence[bool] | None = None,
                       level_slope: float | None = None,
                       search: Representation = "mfcc",
                       contested: Sequence[Word] = (),
                       clear_from_db: float = math.inf,
                       inflected: Sequence[Word] = (),
                       second_opinion: Callable[[list[Word]], list[Word]] | None = None,
                       ) -> tuple[list[Word], list[Word]]:
    """The seeds that sound like the other seeds, and new instances similar to those.

    With ``verify`` set and at least VERIFY_MIN_SEEDS seeds, a seed whose closest other
    seed costs more than ``verify`` times the seeds' median closest cost is dropped: the
    recogniser's false alarms ("rapture", "capsule") rarely sound like the operator's
    other triggers, while the real ones have close siblings. All comparisons are DTW
    costs over the same features, so unlike recogniser scores they compare across spans.
    ``checked`` (one flag per seed) limits the check to some seeds; the others are kept.
    ``second_opinion`` gets the seeds the check would drop and returns those to keep
    after all: a seed unlike the others may be the one trigger of another voice.
    Seeds whose median closest cost exceeds MAX_MUTUAL_COST do not sound alike: all are
    kept, and nothing is searched for.
    A new instance is accepted below ``factor`` times the kept seeds' median closest cost
    (no search where that cost exceeds MAX_MUTUAL_COST),
    plus ``level_slope`` times that cost per dB it is heard less clearly than the seeds
    (``level_slope``, default LEVEL_SLOPE). A span overlapping a word of ``contested``
    (heard as a near-homophone) must cost less than CONTESTED_SHARE of its limit, one heard
    at least ``clear_from_db`` above the noise floor less than CLEAR_SHARE of it (up to
    CLEAR_VOICE_BOOST times more where it matches a seed whose closest sibling is far).
    ``inflected``: spans heard as an inflection of the trigger ("captured") with a pause
    after them, which some voices' triggers are heard as; searched with as templates of
    their own at the same limit (see :func:`_through_inflections`). The check
    always compares MFCCs: on posteriorgrams a voice with few seeds has no close sibling and
    loses them (seeds 1-3, 20 dB: recall 0.99 -> 0.91). The search, the kept seeds' mutual
    cost included, compares frames as ``search`` represents them.
    """
    if len(seeds) < MIN_SEEDS or not activity.segments:
        return list(seeds), []
    checking = verify is not None and len(seeds) >= VERIFY_MIN_SEEDS \
        and (checked is None or any(checked))
    index = SpeechIndex.build(samples, rate, activity, noise_floor,
                              representation="mfcc" if checking else search)
    if index.frames.size == 0:
        return list(seeds), []
    matches, closest = _seed_matches(index, seeds)
    finite = closest[np.isfinite(closest)]
    if finite.size == 0 or float(np.median(finite)) > MAX_MUTUAL_COST:
        return list(seeds), []  # nothing alike to check them against, or to search with
    kept = list(seeds)
    if checking:
        cutoff = verify * float(np.median(finite))
        keep = [k for k in range(len(seeds)) if matches[k] is None
                or closest[k] <= cutoff or (checked is not None and not checked[k])]
        if second_opinion is not None and len(keep) < len(seeds):
            doubted = [k for k in range(len(seeds)) if k not in keep]
            still = set(second_opinion([seeds[k] for k in doubted]))
            keep = sorted(keep + [k for k in doubted if seeds[k] in still])
        kept, matches, closest = [seeds[k] for k in keep], [matches[k] for k in keep], \
            closest[keep]
        if search != "mfcc":
            index = SpeechIndex.build(samples, rate, activity, noise_floor,
                                      representation=search)
            matches, closest = _seed_matches(index, kept)
    finite = closest[np.isfinite(closest)]
    mutual = float(np.median(finite)) if finite.size else math.inf
    if mutual > MAX_MUTUAL_COST:
        return kept, []
    idx = index.frames
    best = _BestMatch(idx.size)
    for k, match in enumerate(matches):
        if match is not None:
            best.merge(*match, template=k)
    spread = np.where(np.isfinite(closest), closest / mutual, 1.0)
    boosts = np.clip(spread, 1.0, CLEAR_VOICE_BOOST)
    slope = LEVEL_SLOPE if level_slope is None else level_slope
    limit = _Limit(mutual, factor, slope, activity,
                   float(np.median([activity.level_db(w.start_s, w.end_s) for w in kept])))
    taken = [(w.start_s, w.end_s) for w in [*kept, *blocked]]
    doubtful = [(w.start_s, w.end_s) for w in contested]
    out: list[Word] = []
    for _ in range(rounds):
        new = _pick(best, idx, limit, taken, doubtful, samples, rate, activity, seeds[0].word,
                    clear_from_db, boosts)
        if not new:
            break
        out += new
        for w in new:
            best.add(index, w)
    # the first search's taken spans include those it turned down: a fresh list
    occupied = [(w.start_s, w.end_s) for w in [*kept, *blocked, *out]]
    out += _through_inflections(index, samples, inflected, limit, occupied, doubtful,
                                seeds[0].word, clear_from_db)
    return kept, sorted(out, key=lambda w: w.start_s)


def _through_inflections(index: SpeechIndex, samples: np.ndarray, inflected: Sequence[Word],
                         limit: _Limit, taken: list[tuple[float, float]],
                         doubtful: list[tuple[float, float]], word: str,
                         clear_from_db: float) -> list[Word]:
    """Triggers found through spans heard as an inflection: the spans below ``limit``
    that such a span matches best, and the span itself, where it found at least
    FOUND_THROUGH_INFLECTION; none overlapping ``taken``, which grows with them."""
    spans = [w for w in inflected
             if not any(w.start_s < b and w.end_s > a for a, b in taken)]
    if not spans:
        return []
    best = _BestMatch(index.frames.size)
    for k, span in enumerate(spans):
        best.add(index, span, template=k)
    taken += [(w.start_s, w.end_s) for w in spans]  # a template does not find itself
    matched: list[int] = []
    found = _pick(best, index.frames, limit, taken, doubtful, samples, index.rate,
                  index.activity, word, clear_from_db, matched=matched)
    counts = Counter(matched)
    confirmed = [Word(word, w.start_s, w.end_s, w.score, "pocketsphinx+similarity")
                 for k, w in enumerate(spans) if counts[k] >= FOUND_THROUGH_INFLECTION]
    return confirmed + [w for w, k in zip(found, matched, strict=True)
                        if counts[k] >= FOUND_THROUGH_INFLECTION]


def _seed_matches(index: SpeechIndex, seeds: list[Word]
                  ) -> tuple[list[tuple[np.ndarray, np.ndarray, int] | None], np.ndarray]:
    """Each seed's DTW match over the index (cost and start per end frame, and template
    length; None for a seed too short), and its cost at its closest other seed."""
    ends = np.searchsorted(index.frames, [int(s.end_s / HOP_S) for s in seeds])
    pair = np.full((len(seeds), len(seeds)), np.inf)
    matches: list[tuple[np.ndarray, np.ndarray, int] | None] = []
    for k, seed in enumerate(seeds):
        template = index.span(seed.start_s, seed.end_s)
        if template.shape[0] < 5:
            matches.append(None)
            continue
        cost, start = subsequence_dtw(template, index.seq)
        matches.append((cost, start, template.shape[0]))
        for q, e in enumerate(ends):
            if q != k and e < cost.size:
                pair[k, q] = cost[max(0, e - SEED_END_TOLERANCE):e + SEED_END_TOLERANCE].min()
    return matches, pair.min(axis=1) if seeds else np.zeros(0)


def fits_template(frames: int, template_frames: int) -> bool:
    """Whether a match of ``frames`` frames may be the template's word said slower or
    faster (MIN_SQUEEZE to MAX_STRETCH times as long)."""
    return MIN_SQUEEZE * template_frames <= frames <= MAX_STRETCH * template_frames


class _Limit:
    """The accepted cost for a span: the seeds' mutual cost times a factor that grows as
    the span is heard less clearly than the seeds."""

    def __init__(self, mutual: float, factor: float, slope: float, activity: VoiceActivity,
                 seed_level_db: float) -> None:
        self.mutual, self.factor, self.slope = mutual, factor, slope
        self.activity, self.seed_level_db = activity, seed_level_db
        #: no span's limit exceeds this: costs above it end the search
        self.highest = mutual * (factor + abs(slope) * MAX_LEVEL_GAP_DB)

    def at(self, start_s: float, end_s: float) -> float:
        """The accepted cost for the span from ``start_s`` to ``end_s``."""
        if self.slope == 0.0:
            return self.mutual * self.factor
        gap = self.seed_level_db - self.activity.level_db(start_s, end_s)
        gap = min(MAX_LEVEL_GAP_DB, max(-MAX_LEVEL_GAP_DB, gap))
        return self.mutual * (self.factor + self.slope * gap)


class _BestMatch:
    """The lowest DTW cost over all templates at each speech frame, and its match start."""

    def __init__(self, n: int) -> None:
        self.cost = np.full(n, np.inf)
        self.start = np.zeros(n, dtype=np.int64)
        self.length = np.zeros(n, dtype=np.int64)
        self.template = np.full(n, -1, dtype=np.int64)  # which seed; -1: a found instance

    def add(self, index: SpeechIndex, word: Word, template: int = -1) -> np.ndarray | None:
        """Match one instance as a template (``template``: its number, see ``merge``); its
        cost per end frame (None if too short)."""
        rows = index.span(word.start_s, word.end_s)
        if rows.shape[0] < 5:
            return None
        cost, start = subsequence_dtw(rows, index.seq)
        self.merge(cost, start, rows.shape[0], template)
        return cost

    def merge(self, cost: np.ndarray, start: np.ndarray, length: int,
              template: int = -1) -> None:
        """Take one template's costs and starts (``template``: the seed's index) where
        they beat the best so far."""
        better = cost < self.cost
        self.cost[better] = cost[better]
        self.start[better] = start[better]
        self.length[better] = length
        self.template[better] = template


def _pick(best: _BestMatch, idx: np.ndarray, limit: _Limit, taken: list[tuple[float, float]],
          doubtful: list[tuple[float, float]], samples: np.ndarray, rate: int,
          activity: VoiceActivity, word: str, clear_from_db: float = math.inf,
          boosts: np.ndarray | None = None, matched: list[int] | None = None) -> list[Word]:
    """Non-overlapping matches below their limit (CONTESTED_SHARE of it where they overlap
    a ``doubtful`` span, times CLEAR_SHARE where heard at least ``clear_from_db`` above the
    noise floor, that times the matched seed's entry of ``boosts``), best first; ``taken``
    grows with them, and ``matched`` with the number of each one's template."""
    out: list[Word] = []
    words = list(taken)  # the seeds' and other words' spans: a find's bounds keep off them
    for j in np.argsort(best.cost):
        c = float(best.cost[j])
        if c >= limit.highest:
            break
        s_frame, e_frame = int(idx[best.start[j]]), int(idx[j]) + 1
        if not fits_template(e_frame - s_frame, int(best.length[j])):
            continue
        ts, te = s_frame * HOP_S, e_frame * HOP_S
        if any(ts < b and te > a for a, b in taken):
            continue
        taken.append((ts, te))  # the best match of a span decides it, accepted or not
        share = CONTESTED_SHARE if any(ts < b and te > a for a, b in doubtful) else 1.0
        if activity.level_db(ts, te) >= clear_from_db:
            seed = int(best.template[j])
            share *= CLEAR_SHARE * (boosts[seed] if boosts is not None and seed >= 0 else 1.0)
        if c >= share * limit.at(ts, te):
            continue
        bounds = word_bounds(samples, rate, ts, te, activity.floor_at((ts + te) / 2))
        if bounds.runs_on:
            continue  # the template matched the start of a longer word ("captured it?")
        if any(bounds.start_s < b and bounds.end_s > a for a, b in words):
            continue  # its sound reaches into a word already there
        words.append((bounds.start_s, bounds.end_s))
        out.append(Word(word, bounds.start_s, bounds.end_s, max(0.0, 1.0 - c),
                        "pocketsphinx+similarity"))
        if matched is not None:
            matched.append(int(best.template[j]))
    return out
