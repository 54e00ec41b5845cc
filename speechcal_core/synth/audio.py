"""Render the microphone track of a synthetic session (``OUT/audio.ogg``) and its truth."""

from __future__ import annotations

import math
from bisect import bisect_left
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
import soundfile as sf
from scipy.signal import butter, fftconvolve, lfilter, resample_poly, sosfilt

from speechcal_core.synth.voices import Clip, VoiceBank, check_trigger_word, load_bank

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from speechcal_core.synth.timeline import SpeechSlot, Timeline

SAMPLE_RATE = 48_000
WRITE_BLOCK = 4096  # frames per soundfile write (libsndfile Ogg pitfall, DESIGN.md §5)
SPEECH_RMS = 0.035  # about -29 dBFS while speaking, before per-instance gain
GAIN_DB = (-4.0, 3.0)  # per spoken instance
RATE_RANGE = (0.95, 1.05)  # resampling factor: pitch and tempo together
RT60_RANGE = (0.15, 0.5)
CLAP_PEAK = 0.85
DOOR_PEAK = 0.55
PEAK_LIMIT = 0.98  # the whole mix is scaled down (ratios kept) if it could exceed this
NOISE_CREST = 5.0  # noise peaks assumed up to this many RMS when sizing the headroom
CHUNK_S = 10.0  # rendered and written piece by piece: memory does not grow with duration
SPEECH_GUARD_S = 0.15  # a distractor keeps this far from any trigger
PRE_CLAP_GAP_S = (0.2, 1.0)  # the pre-clap chatter ends this long before the first clap
PRE_CLAP_TEXTS = ("ready", "okay")
NEAR_HOMOPHONE_P = 0.45
#: trigger words come from voices built from human recordings; espeak-ng's formant voices
#: only speak distractors (speech recognisers hardly know them)
TRIGGER_ENGINES = ("flite",)
DOOR_CLEAR_S = (0.3, 0.8)  # no chatter this long before / after the door bang's onset


@dataclass
class AudioTruth:
    """Where everything audible was placed, in audio seconds (the microphone's clock)."""

    triggers: list[dict] = field(default_factory=list)  # word, start_s, end_s, hold, ...
    distractors: list[dict] = field(default_factory=list)  # text, start_s, end_s, ...
    claps: list[float] = field(default_factory=list)  # onset (start of the attack)
    events: list[dict] = field(default_factory=list)  # other transients: kind, audio_s
    sample_rate: int = SAMPLE_RATE
    duration_s: float = 0.0
    speech_rms: float = 0.0  # RMS of the speech track inside the spoken intervals
    noise_rms: float = 0.0  # RMS of the background noise over the whole file


@dataclass(frozen=True)
class _Placed:
    """One spoken instance: which clip, where, how."""

    kind: str
    clip: Clip
    start_s: float
    end_s: float
    rate: float
    hold: int = -1
    gain: float = SPEECH_RMS  # RMS of the loud part of the dry clip
    drr_db: float = 6.0  # direct-to-reverberant ratio of its room response
    ir_seed: int = 0

    @property
    def first_sample(self) -> int:
        """Index of the first output sample the dry clip touches."""
        return math.ceil(self.start_s * SAMPLE_RATE)


def render_audio(
    timeline: Timeline, out_path: Path, progress: Callable[[float], None] | None = None
) -> AudioTruth:
    """Write the session's microphone track to ``out_path`` (Ogg Vorbis, 48 kHz mono).

    Speech, claps and a door bang are placed at ``timeline.sync.to_audio(session_ns)``,
    so offset and drift are built in; background noise is scaled to ``options.snr_db``.
    Raises UsageError when the trigger word has no bundled clips.
    """
    report = progress or (lambda _f: None)
    word = check_trigger_word(timeline.options.trigger_word)
    bank = load_bank()
    sync = timeline.sync
    n = math.ceil(timeline.audio_duration_s * SAMPLE_RATE)
    rng = timeline.rng("audio")
    ev_rng = timeline.rng("audio-events")
    rt60 = float(rng.uniform(*RT60_RANGE))
    claps_s = [float(sync.to_audio(c)) for c in timeline.claps_ns]

    placed = _plan_speech(timeline, bank, word, claps_s, rng)
    door_s = _door_time(placed, claps_s, n / SAMPLE_RATE, ev_rng)
    # chatter never shares the door's moment, so speech and transients stay separable
    placed = [p for p in placed if p.kind == "trigger"
              or p.end_s + DOOR_CLEAR_S[0] <= door_s or p.start_s >= door_s + DOOR_CLEAR_S[1]]
    placed = [replace(p, gain=SPEECH_RMS * 10 ** (rng.uniform(*GAIN_DB) / 20),
                      drr_db=float(rng.uniform(4.0, 10.0)), ir_seed=int(rng.integers(2**31)))
              for p in placed]
    transients = [(math.ceil(t0 * SAMPLE_RATE), _clap(ev_rng, t0, rt60)) for t0 in claps_s]
    transients.append((math.ceil(door_s * SAMPLE_RATE), _door(ev_rng, door_s)))
    bounds = np.linspace(0, n, max(1, round(n / (CHUNK_S * SAMPLE_RATE))) + 1).astype(int)
    report(0.02)

    # pass 1, speech only: its level inside the spoken intervals and its peak
    spans = [(p.first_sample, math.ceil(p.end_s * SAMPLE_RATE)) for p in placed]
    energy, count, speech_peak = 0.0, 0, 0.0
    for a, b, buf in _speech_chunks(bank, placed, rt60, bounds):
        inside = buf[_mask(spans, a, b)]
        energy += float(np.sum(inside**2))
        count += len(inside)
        speech_peak = max(speech_peak, float(np.max(np.abs(buf))))
    report(0.15)
    speech_rms = math.sqrt(energy / count) if count else SPEECH_RMS
    noise_rms = speech_rms / 10 ** (timeline.options.snr_db / 20)
    loudest = max([speech_peak] + [float(np.max(np.abs(sig))) for _, sig in transients])
    scale = min(1.0, PEAK_LIMIT / (loudest + NOISE_CREST * noise_rms))

    # pass 2: speech + noise + transients, scaled, written chunk by chunk
    noise = _RoomNoise(timeline.rng("audio-noise"))
    with sf.SoundFile(str(out_path), "w", SAMPLE_RATE, 1, format="OGG",
                      subtype="VORBIS") as f:
        for a, b, buf in _speech_chunks(bank, placed, rt60, bounds):
            buf += noise_rms * noise.take(b - a)
            for k0, sig in transients:
                _add_at_index(buf, k0 - a, sig)
            buf *= scale
            np.clip(buf, -1.0, 1.0, out=buf)
            chunk = buf.astype(np.float32)
            for i in range(0, len(chunk), WRITE_BLOCK):  # DESIGN.md §5: small writes
                f.write(chunk[i:i + WRITE_BLOCK])
            report(0.15 + 0.85 * b / n)
    truth = AudioTruth(
        triggers=[{"word": p.clip.text, "start_s": p.start_s, "end_s": p.end_s, "hold": p.hold,
                   "voice": p.clip.voice, "clip": p.clip.file}
                  for p in placed if p.kind == "trigger"],
        distractors=[{"text": p.clip.text, "start_s": p.start_s, "end_s": p.end_s,
                      "voice": p.clip.voice, "near": p.clip.near}
                     for p in placed if p.kind == "distractor"],
        claps=claps_s,
        events=[{"kind": "door", "audio_s": door_s,
                 "session_ns": int(sync.to_session(door_s))}],
        sample_rate=SAMPLE_RATE,
        duration_s=n / SAMPLE_RATE,
        speech_rms=speech_rms * scale,
        noise_rms=noise_rms * scale,
    )
    return truth


def _plan_speech(
    timeline: Timeline, bank: VoiceBank, word: str, claps_s: list[float],
    rng: np.random.Generator,
) -> list[_Placed]:
    """Pick a clip, rate and position for every speech slot plus the pre-clap chatter."""
    sync = timeline.sync
    triggers = [c for c in bank.select("trigger", word) if c.engine in TRIGGER_ENGINES]
    triggers = triggers or bank.select("trigger", word)
    distractors = bank.select("distractor")
    placed: list[_Placed] = []
    for slot in timeline.speech:
        if slot.kind != "trigger":
            continue
        clip = triggers[int(rng.integers(len(triggers)))]
        rate = float(rng.uniform(*RATE_RANGE))
        placed.append(_position("trigger", clip, rate, float(sync.to_audio(slot.anchor_ns)),
                                slot.align, slot.hold))
    busy = [(p.start_s - SPEECH_GUARD_S, p.end_s + SPEECH_GUARD_S) for p in placed]
    for slot in timeline.speech:
        if slot.kind != "distractor":
            continue
        anchor = float(sync.to_audio(slot.anchor_ns))
        rate = float(rng.uniform(*RATE_RANGE))
        near = rng.random() < NEAR_HOMOPHONE_P
        pool = [c for c in distractors if (c.near == word) == near]
        fits = [c for c in pool if _fits(c, rate, anchor, slot, busy)]
        if not fits:
            fits = [c for c in distractors if _fits(c, rate, anchor, slot, busy)]
        if not fits:
            continue  # nothing fits between the triggers: leave the move silent
        clip = fits[int(rng.integers(len(fits)))]
        placed.append(_position("distractor", clip, rate, anchor, slot.align))
    if claps_s:
        # hard case for clap detection: short speech ending just before the first clap
        pool = [c for c in distractors if c.text in PRE_CLAP_TEXTS]
        clip = pool[int(rng.integers(len(pool)))]
        rate = float(rng.uniform(*RATE_RANGE))
        end = claps_s[0] - float(rng.uniform(*PRE_CLAP_GAP_S))
        if end - clip.duration_s / rate > 0.05:
            placed.append(_position("distractor", clip, rate, end, "end"))
    placed.sort(key=lambda p: p.start_s)
    return placed


def _position(kind: str, clip: Clip, rate: float, anchor_s: float, align: str,
              hold: int = -1) -> _Placed:
    """Place a clip so its midpoint (``center``) or end (``end``) is at ``anchor_s``."""
    dur = clip.duration_s / rate
    start = anchor_s - dur / 2 if align == "center" else anchor_s - dur
    return _Placed(kind, clip, start, start + dur, rate, hold)


def _fits(clip: Clip, rate: float, anchor: float, slot: SpeechSlot,
          busy: list[tuple[float, float]]) -> bool:
    """Whether the clip is short enough for the slot and clear of the triggers."""
    if clip.duration_s / rate > slot.max_duration_s:
        return False
    p = _position("distractor", clip, rate, anchor, slot.align)
    return all(p.end_s <= a or p.start_s >= b for a, b in busy)


def _mask(spans: list[tuple[int, int]], a: int, b: int) -> np.ndarray:
    """Boolean mask of samples [a, b) inside any of the sorted sample spans."""
    mask = np.zeros(b - a, dtype=bool)
    longest = max((e - s for s, e in spans), default=0)
    j = bisect_left(spans, (a - longest, -1))
    while j < len(spans) and spans[j][0] < b:
        s0, s1 = spans[j]
        if s1 > a:
            mask[max(s0, a) - a:min(s1, b) - a] = True
        j += 1
    return mask


def _speech_chunks(bank: VoiceBank, placed: list[_Placed], rt60: float,
                   bounds: np.ndarray) -> Iterator[tuple[int, int, np.ndarray]]:
    """Yield ``(a, b, speech[a:b])`` chunk by chunk; each instance is rendered when reached."""
    order = sorted(placed, key=lambda p: p.first_sample)
    active: list[tuple[int, np.ndarray]] = []
    i = 0
    for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        while i < len(order) and order[i].first_sample < b:
            active.append(_render_instance(bank, order[i], rt60))
            i += 1
        buf = np.zeros(b - a)
        for k0, sig in active:
            _add_at_index(buf, k0 - a, sig)
        active = [(k0, sig) for k0, sig in active if k0 + len(sig) > b]
        yield a, b, buf


def _render_instance(bank: VoiceBank, item: _Placed, rt60: float) -> tuple[int, np.ndarray]:
    """Resample the clip to 48 kHz at its rate, place it sub-sample exactly, add reverb.

    Returns the first sample index and the wet signal; deterministic for an instance.
    """
    x = bank.samples(item.clip)
    g = math.gcd(bank.sample_rate, SAMPLE_RATE)
    x = resample_poly(x, SAMPLE_RATE // g, bank.sample_rate // g)
    x = x * (item.gain / _active_rms(x))
    k0 = item.first_sample
    k1 = math.ceil(item.end_s * SAMPLE_RATE)
    # output sample k sits at clip time (k / sr - start) * rate
    pos = (np.arange(k0, k1) / SAMPLE_RATE - item.start_s) * item.rate * SAMPLE_RATE
    dry = np.interp(pos, np.arange(len(x)), x, left=0.0, right=0.0)
    ir = _room_ir(np.random.default_rng(item.ir_seed), rt60, item.drr_db)
    return k0, fftconvolve(dry, ir)


def _active_rms(x: np.ndarray) -> float:
    """RMS over the louder half of 10 ms frames (speech level, pauses inside ignored)."""
    fr = SAMPLE_RATE // 100
    m = max(1, len(x) // fr)
    frames = np.mean(np.resize(x, m * fr).reshape(m, fr) ** 2, axis=1)
    loud = np.sort(frames)[m // 2:]
    return float(np.sqrt(np.mean(loud))) or 1.0


def _room_ir(rng: np.random.Generator, rt60: float, direct_to_reverb_db: float) -> np.ndarray:
    """Synthetic room response: unit direct path, then exponentially decaying noise."""
    rt = rt60 * float(rng.uniform(0.85, 1.15))
    n = int(rt * SAMPLE_RATE)
    pre = int(rng.uniform(0.002, 0.008) * SAMPLE_RATE)
    t = np.arange(n) / SAMPLE_RATE
    tail = rng.standard_normal(n) * np.exp(-6.91 * t / rt)
    tail *= 10 ** (-direct_to_reverb_db / 20) / float(np.sqrt(np.sum(tail**2)))
    ir = np.zeros(pre + n)
    ir[0] = 1.0
    ir[pre:] += tail
    return ir


def _clap(rng: np.random.Generator, t0: float, rt60: float) -> np.ndarray:
    """A hand clap whose attack starts exactly at audio time ``t0``.

    Returns samples from ``ceil(t0 * sr)`` on: band-emphasised noise (1-4 kHz) under a
    sub-millisecond linear rise and a 30-80 ms exponential decay, plus a little reverb.
    """
    n = int(0.12 * SAMPLE_RATE)
    pre = 256  # filter settling, cut before the envelope is applied
    white = rng.standard_normal(n + pre)
    band = sosfilt(butter(2, (1000, 4000), "bandpass", fs=SAMPLE_RATE, output="sos"), white)
    noise = (band / np.std(band) + 0.35 * white / np.std(white))[pre:]
    t = (math.ceil(t0 * SAMPLE_RATE) + np.arange(n)) / SAMPLE_RATE - t0  # >= 0
    rise = float(rng.uniform(0.0002, 0.0006))
    tau = float(rng.uniform(0.03, 0.08)) / 6.91  # 60 dB down after 30-80 ms
    env = np.minimum(t / rise, 1.0) * np.exp(-np.maximum(t - rise, 0.0) / tau)
    dry = noise * env
    wet = fftconvolve(dry, _room_ir(rng, rt60, direct_to_reverb_db=12.0))
    return wet * (CLAP_PEAK / float(np.max(np.abs(wet))))


def _door(rng: np.random.Generator, t0: float) -> np.ndarray:
    """A door bang starting at ``t0``: low thump, 5-12 ms rise, 0.12-0.25 s decay."""
    n = int(1.2 * SAMPLE_RATE)
    t = (math.ceil(t0 * SAMPLE_RATE) + np.arange(n)) / SAMPLE_RATE - t0
    rise = float(rng.uniform(0.005, 0.012))
    tau = float(rng.uniform(0.12, 0.25))
    env = np.where(t < rise, 0.5 - 0.5 * np.cos(np.pi * np.minimum(t / rise, 1.0)), 1.0)
    env *= np.exp(-np.maximum(t - rise, 0.0) / tau)
    low = sosfilt(butter(2, 250, "lowpass", fs=SAMPLE_RATE, output="sos"),
                  rng.standard_normal(n))
    low /= np.std(low)
    f1, f2 = float(rng.uniform(55, 90)), float(rng.uniform(120, 180))
    body = (np.sin(2 * np.pi * f1 * t) + 0.5 * np.sin(2 * np.pi * f2 * t)
            + 0.6 * low + 0.08 * rng.standard_normal(n))
    sig = body * env
    return sig * (DOOR_PEAK / float(np.max(np.abs(sig))))


def _door_time(placed: list[_Placed], claps_s: list[float], duration_s: float,
               rng: np.random.Generator) -> float:
    """A moment for the door bang, mid-session and away from triggers.

    Preference: the middle half of the session, at least 1 s from any speech; then 1 s
    from triggers only (chatter may overlap); then anywhere after the first clap; the
    farthest point from triggers if nothing qualifies. Always 2 s from claps.
    """
    first = claps_s[0] + 2.0 if claps_s else 1.0
    grid = np.arange(first, max(first + 0.01, duration_s - 1.5), 0.01)

    def clearance(items: list[_Placed]) -> np.ndarray:
        dist = np.full(len(grid), np.inf)
        for p in items:
            d = np.maximum(p.start_s - grid, grid - (p.end_s + 0.3))  # 0.3 s: reverb tail
            dist = np.minimum(dist, np.maximum(d, 0.0))
        for c in claps_s:
            dist = np.minimum(dist, np.abs(grid - c) / 2)
        return dist

    middle = (grid >= 0.25 * duration_s) & (grid <= 0.75 * duration_s)
    from_all = clearance(placed)
    from_triggers = clearance([p for p in placed if p.kind == "trigger"])
    for ok in (middle & (from_all >= 1.0), middle & (from_triggers >= 1.0),
               from_all >= 1.0, from_triggers >= 1.0):
        idx = np.flatnonzero(ok)
        if len(idx):
            return float(grid[idx[int(rng.integers(len(idx)))]])
    return float(grid[int(np.argmax(from_triggers))])


class _RoomNoise:
    """Room tone (pink plus a little brown), mains hum and faint breathing, as a stream.

    Filter states carry over between pieces; each piece is scaled to unit RMS, so the
    whole file's noise RMS is exactly the factor applied to it.
    """

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.pink_ba = ([0.049922035, -0.095993537, 0.050612699, -0.004408786],
                        [1.0, -2.494956002, 2.017265875, -0.522189400])
        self.brown_ba = ([1.0], [1.0, -0.995])
        self.hp = butter(2, 25, "highpass", fs=SAMPLE_RATE, output="sos")
        self.bp = butter(2, (400, 2500), "bandpass", fs=SAMPLE_RATE, output="sos")
        self.pink_std = _impulse_std(*self.pink_ba)
        self.brown_std = _impulse_std(*self.brown_ba)
        self.zi_pink = np.zeros(3)
        self.zi_brown = np.zeros(1)
        self.zi_hp = np.zeros((self.hp.shape[0], 2))
        self.zi_bp = np.zeros((self.bp.shape[0], 2))
        t = np.arange(SAMPLE_RATE) / SAMPLE_RATE  # one second holds whole hum periods
        mains = 50.0 if rng.random() < 0.5 else 60.0
        self.hum = sum(a * np.sin(2 * np.pi * mains * h * t + rng.uniform(0, 2 * np.pi))
                       for h, a in ((1, 0.12), (2, 0.05), (3, 0.03)))
        self.breath_std = float(np.sqrt(np.sum(sosfilt(self.bp, np.eye(1, 1 << 14)[0]) ** 2)))
        self.breath_period = float(rng.uniform(3.5, 5.0))
        self.breath_phase = float(rng.uniform(0, 2 * np.pi))
        self.pos = 0
        self._raw(SAMPLE_RATE // 2)  # settle the filters

    def _raw(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """Unscaled room tone and breath noise for the next m samples."""
        pink, self.zi_pink = lfilter(*self.pink_ba, self.rng.standard_normal(m),
                                     zi=self.zi_pink)
        brown, self.zi_brown = lfilter(*self.brown_ba, self.rng.standard_normal(m),
                                       zi=self.zi_brown)
        room, self.zi_hp = sosfilt(self.hp, pink / self.pink_std + 0.5 * brown / self.brown_std,
                                   zi=self.zi_hp)
        breath, self.zi_bp = sosfilt(self.bp, self.rng.standard_normal(m), zi=self.zi_bp)
        return room, breath

    def take(self, m: int) -> np.ndarray:
        """The next m samples at unit RMS."""
        room, breath = self._raw(m)
        idx = self.pos + np.arange(m)
        hum = self.hum[idx % SAMPLE_RATE]
        hop = SAMPLE_RATE // 100  # the breathing envelope changes slowly: 10 ms steps
        tc = (idx[::hop] / SAMPLE_RATE) * (2 * np.pi / self.breath_period) + self.breath_phase
        cycle = np.repeat(np.maximum(np.sin(tc), 0.0) ** 2, hop)[:m]
        self.pos += m
        out = room / max(float(np.std(room)), 1e-12) + hum + 0.3 * cycle * breath / self.breath_std
        return out / max(float(np.sqrt(np.mean(out**2))), 1e-12)


def _impulse_std(b: list[float], a: list[float]) -> float:
    """Output standard deviation of the filter b/a driven by unit white noise."""
    impulse = np.zeros(1 << 17)
    impulse[0] = 1.0
    return float(np.sqrt(np.sum(lfilter(b, a, impulse) ** 2)))


def _add_at_index(out: np.ndarray, k0: int, sig: np.ndarray) -> None:
    """Add ``sig`` starting at sample ``k0``, clipped to the buffer."""
    a, b = max(0, k0), min(len(out), k0 + len(sig))
    if b > a:
        out[a:b] += sig[a - k0:b - k0]
