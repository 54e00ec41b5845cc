"""The grammars spans are decoded with: one tier per how clearly a span is heard.

A span is decoded with one finite-state grammar looping over the trigger words (free),
their rivals (inflections, at a small prior), their confusables (near-homophones, at a
smaller prior, per tier) and the phones (a filler, at a cost per phone that the
sensitivity sets). The tier is picked by the span's level above the noise floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from speechcal_core.speech.matching import DEFAULT_SENSITIVITY

if TYPE_CHECKING:
    from speechcal_core.speech.matching import TriggerSpec


@dataclass(frozen=True)
class Tier:
    """How to decode spans heard at least ``min_level_db`` above the noise floor.

    ``phone_log10``: log10 cost of one filler phone at sensitivity 0, at the default
    (DEFAULT_SENSITIVITY) and at 1 (a dearer filler lets more words pass).
    ``confusable_log10``: log10 prior of a confusable word ("rapture", "captor") against
    a trigger, or None to leave them out.
    """

    min_level_db: float
    #: Above the default the cost grows three times as fast as below it: the default is
    #: tuned on "capture", and other words need a much dearer filler to pass. Seeds 1-3,
    #: sensitivity 1, recall at 20 / 10 / 5 dB, clearest tier's cost -11 -> -19:
    #: "record" 0.77 / 0.65 / 0.44 -> 0.83 / 0.82 / 0.52, "snapshot" 0.82 / 0.70 / 0.46
    #: -> 0.97 / 0.88 / 0.61; precision the same or better except at 5 dB
    phone_log10: tuple[float, float, float] = (-3.0, -7.0, -19.0)
    #: a span whose loudest moment (PEAK_PERCENTILE) stands this high takes this tier
    #: too, whatever its level: a short word in a long span has a low level
    min_peak_db: float | None = None
    confusable_log10: float | None = None
    #: log10 prior of a rival (an inflection) against a trigger: operators say the
    #: trigger far more often, and some voices end "capture" so it sounds like "captured"
    rival_log10: float = -2.0


#: from the clearest spans down; the last tier takes everything else
TIERS: tuple[Tier, ...] = (
    Tier(18.0, confusable_log10=-10.0),
    #: a dearer filler in noisier spans: the recogniser's triggers there are the templates
    #: that find the rest, and a voice it misses entirely is lost (tuning seeds 101-112,
    #: 5 dB: a quiet female voice had no trigger found in two sessions at (-3, -11))
    #: Near-homophones compete here too, at a smaller prior: where the recogniser hears
    #: "rapture" the similarity search needs a much closer match (CONTESTED_SHARE), and
    #: most of its false alarms were such raptures. Seeds 1-3, 5 dB precision 0.947 ->
    #: 0.975, 10 dB 0.971 -> 0.990, recall unchanged; seeds 101-124 at 10 dB 0.951 ->
    #: 0.959 (same recall), at 5 dB 0.932 -> 0.939 (recall 0.910 -> 0.908). The clear
    #: tier's -10 here lost a 10 dB trigger more.
    Tier(12.0, phone_log10=(-5.0, -9.0, -21.0), min_peak_db=14.0, confusable_log10=-12.0),
    #: dearer still in the noisiest spans, now that the posteriorgram search turns the
    #: extra triggers into templates for the rest. Seeds 101-124: 5 dB recall / precision
    #: 0.885 / 0.920 -> 0.910 / 0.926, 10 dB unchanged. The same filler for every span
    #: below 18 dB cost 15 more false alarms at 10 dB; without the peak condition above,
    #: "captain" at the end of a long quiet span passed as the trigger
    Tier(-math.inf, phone_log10=(-7.0, -11.0, -23.0), confusable_log10=-12.0),
)
PEAK_PERCENTILE = 98.0


def search_name(sensitivity: float, level_db: float, peak_db: float = -math.inf) -> str:
    """The grammar (one per tier and sensitivity) for a span at ``level_db`` above the
    noise floor whose loudest moment stands ``peak_db`` above it."""
    return grammar_name(sensitivity, tier_index(level_db, peak_db))


def grammar_name(sensitivity: float, tier: int) -> str:
    return f"tier{tier}@{sensitivity:g}"


def tier_index(level_db: float, peak_db: float = -math.inf) -> int:
    """The tier of a span at ``level_db`` above the noise floor whose loudest moment
    stands ``peak_db`` above it."""
    for k, tier in enumerate(TIERS):
        if level_db >= tier.min_level_db or (
                tier.min_peak_db is not None and peak_db >= tier.min_peak_db):
            return k
    return len(TIERS) - 1


def phone_log10(tier: Tier, sensitivity: float) -> float:
    """The log10 cost of one filler phone in ``tier`` at ``sensitivity`` (0..1): linear
    from 0 to the default and from the default to 1."""
    return float(np.interp(sensitivity, (0.0, DEFAULT_SENSITIVITY, 1.0), tier.phone_log10))


def spot_grammar(logmath: Any, spec: TriggerSpec, rivals: list[str], confusables: list[str],
                  phones: list[str], tier: Tier) -> Any:
    """One state looping over triggers (free), rivals and confusable words (at the tier's
    priors; confusables only if it has one) and phones (at a cost each)."""
    phone_cost = int(logmath.log(10.0) * phone_log10(tier, spec.sensitivity))
    rival_cost = int(logmath.log(10.0) * tier.rival_log10)
    words = [(w, 0) for w in spec.words] + [(w, rival_cost) for w in rivals]
    if tier.confusable_log10 is not None:
        cost = int(logmath.log(10.0) * tier.confusable_log10)
        words += [(w, cost) for w in confusables]
    words += [(w, phone_cost) for w in phones]
    return word_loop(logmath, "spot", words)


def word_loop(logmath: Any, name: str, words: list[tuple[str, int]]) -> Any:
    """A grammar of one state looping over ``words`` (word, log cost), then ending."""
    import pocketsphinx

    fsg = pocketsphinx.FsgModel(name, logmath, 1.0, 2)
    for w, cost in words:
        fsg.trans_add(0, 0, cost, fsg.word_add(w))
    fsg.null_trans_add(0, 1, 0)
    fsg.set_start_state(0)
    fsg.set_final_state(1)
    return fsg
