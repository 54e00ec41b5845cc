"""Decoding voice-active spans with pocketsphinx: span by span, in chunks that start alike,
by worker processes where there are several cores.

pocketsphinx's front end carries its state (cepstral mean, noise estimate) from one
utterance to the next, so what is heard in a span depends a little on the spans before.
Each chunk therefore starts from a fresh front end warmed up on the span before it: the
words are the same in whatever order, and in however many processes, chunks are decoded.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, wait
from concurrent.futures.process import BrokenProcessPool
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from speechcal_core.processes import spawn_can_start, usable_cores
from speechcal_core.speech.backend import Word
from speechcal_core.speech.decoding_workers import (
    decoding_pool,
    discard_decoding_pool,
    note_served,
    pool_running,
    workers_usable,
)
from speechcal_core.speech.lexicon import dictionary_word

if TYPE_CHECKING:
    from speechcal_core.speech.matching import TriggerSpec

RATE = 16000  # the model's
FRAME_S = 0.01
PEAK_LEVEL = 0.7  # each span is scaled to this peak before 16-bit conversion
#: spans are decoded in chunks of at least this much audio, each by a fresh front end
#: warmed up on the span before the chunk (``decode_chunk``). Found / false alarms, every
#: span decoded after the one before -> in chunks: 5 dB seeds 101-124 930 / 52 -> 930 /
#: 51, 125-148 931 / 63 -> 926 / 63; 10 dB the same (962 / 31, 954 / 28); the
#: benchmark's seeds 1-3 the same at 20, 10 and 5 dB. Not warmed up: 101-124 at 5 dB
#: 931 / 56; warmed up on 8 s of spans before: 930 / 54, 925 / 63
CHUNK_S = 15.0
#: the search a decoder warms up with: a grammar of one phone (the backend's), so that it
#: costs a tenth of decoding
WARM_UP_SEARCH = "warm-up"
#: below this much speech, starting worker processes costs more than they save (each
#: takes about 1.5 s to import and build its decoder); workers already up take any
MIN_PARALLEL_S = 60.0
#: worker processes at most (each holds the model, dictionary and grammars: 215 MB)
MAX_WORKERS = 4


class Span(NamedTuple):
    """A voice-active span to decode: where it starts (audio seconds), its samples and
    the grammar (search) to decode it with."""

    start_s: float
    samples: np.ndarray
    search: str


class Chunk(NamedTuple):
    """Consecutive spans to decode, and the samples of the span before them (None for the
    first chunk) to warm the front end up on."""

    warm_up: np.ndarray | None
    spans: list[Span]


def default_workers() -> int:
    """Processes decoding at once unless told: one per usable core, up to MAX_WORKERS."""
    return min(MAX_WORKERS, usable_cores())


def decode_spans(spans: list[Span], spec: TriggerSpec,
                 decode_here: Callable[[Chunk], list[Word]], workers: int,
                 report: Callable[[float], None]) -> tuple[list[Word], float]:
    """The words heard in ``spans`` and the CPU seconds worker processes spent on them.

    The spans are decoded in chunks (CHUNK_S): by ``workers`` worker processes (decoding
    for ``spec``) where there are several and enough speech, else by ``decode_here``;
    the same words either way. ``report`` gets the share of the spans done (0..1); it
    may raise to stop.
    """
    chunks = _chunks(spans)
    seconds = [sum(span.samples.size for span in chunk.spans) / RATE for chunk in chunks]
    total = sum(seconds) or 1.0
    worth_it = total >= MIN_PARALLEL_S or pool_running(workers)
    if workers > 1 and len(chunks) > 1 and worth_it and spawn_can_start() \
            and workers_usable():
        try:
            return _decode_in_workers(chunks, seconds, spec, workers, report)
        except BrokenProcessPool:
            discard_decoding_pool()  # a worker died (out of memory?): decode here
    found: list[Word] = []
    done = 0.0
    for chunk, length in zip(chunks, seconds, strict=True):
        report(done / total)
        found += decode_here(chunk)
        done += length
    return found, 0.0


def _decode_in_workers(chunks: list[Chunk], seconds: list[float], spec: TriggerSpec,
                       workers: int, report: Callable[[float], None]
                       ) -> tuple[list[Word], float]:
    """``decode_spans`` by the worker processes; progress as chunks come back."""
    cpu_s = 0.0
    with decoding_pool(workers) as pool:  # a worker starts only when needed
        futures = [pool.submit(_decode_chunk_in_worker, spec, chunk) for chunk in chunks]
        length = dict(zip(futures, seconds, strict=True))
        total, done = sum(seconds), 0.0
        pending: set[Future] = set(futures)
        try:
            while pending:
                report(done / total)
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    cpu_s += future.result()[1]
                    note_served()
                    done += length[future]
        finally:
            for future in pending:  # stopped: chunks not yet begun are not decoded
                future.cancel()
    return [word for future in futures for word in future.result()[0]], cpu_s


def _chunks(spans: list[Span]) -> list[Chunk]:
    """``spans`` in consecutive chunks of at least CHUNK_S of audio (the last may be
    shorter)."""
    chunks: list[Chunk] = []
    length = math.inf
    for k, span in enumerate(spans):
        if length >= CHUNK_S:
            chunks.append(Chunk(spans[k - 1].samples if k else None, []))
            length = 0.0
        chunks[-1].spans.append(span)
        length += span.samples.size / RATE
    return chunks


def decode_chunk(decoder: Any, chunk: Chunk, vocab: set[str]) -> list[Word]:
    """The words of ``vocab`` in the chunk's spans, decoded one after the other by a fresh
    front end warmed up on its ``warm_up`` samples (the decoder has WARM_UP_SEARCH): each
    chunk starts alike, whatever the decoder decoded before."""
    decoder.reinit_feat()
    if chunk.warm_up is not None:
        decoder.activate_search(WARM_UP_SEARCH)
        decode_span(decoder, chunk.warm_up, 0.0, set())
    found: list[Word] = []
    for span in chunk.spans:
        decoder.activate_search(span.search)
        found += decode_span(decoder, span.samples, span.start_s, vocab)
    return found


def decode_span(decoder: Any, samples: np.ndarray, offset_s: float,
                vocab: set[str]) -> list[Word]:
    """Decode one span with the active search; words of ``vocab`` in audio seconds.

    The score is the word's acoustic score relative to the best partial path of each of
    its frames (1.0: the best explanation everywhere).
    pocketsphinx's cepstral mean is live whatever the model's ``-cmn batch`` says: a span
    starts from the mean the previous one left (``decode_chunk`` starts each chunk
    afresh), so what is heard in it depends a little on the span before. Starting each
    span from its own mean (a front-end pass before decoding) moved single 5 dB sessions
    by up to ten triggers either way but not the total: seeds 101-148, 1824 found / 110
    false -> 1822 / 117 (its mean with 2 s around it: 1823 / 115; both decodings' words
    together: 1847 / 118 at a third more CPU).
    """
    peak = float(np.max(np.abs(samples))) if samples.size else 0.0
    if peak <= 0.0 or samples.size < RATE // 10:
        return []
    pcm = (samples * (PEAK_LEVEL * 32767 / peak)).astype(np.int16).tobytes()
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()
    out = []
    for seg in decoder.seg() or []:
        word = dictionary_word(seg.word)
        if word not in vocab:
            continue
        start = offset_s + seg.start_frame * FRAME_S
        end = offset_s + (seg.end_frame + 1) * FRAME_S
        out.append(Word(word, start, end, float(min(1.0, max(0.0, seg.ascore))),
                        "pocketsphinx"))
    return out


#: the backend of a worker process, kept for its decoders between chunks
_worker_backend: Any = None


def _decode_chunk_in_worker(spec: TriggerSpec, chunk: Chunk) -> tuple[list[Word], float]:
    """One chunk decoded in a worker process, and the CPU seconds it took there."""
    from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend

    global _worker_backend
    started = time.process_time()
    if _worker_backend is None:
        _worker_backend = PocketsphinxBackend(workers=1)
    words = _worker_backend.decode_chunk(spec, chunk)
    return words, time.process_time() - started
