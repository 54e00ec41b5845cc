"""Raw encodings to mono/BGR images: layouts, step padding, byte order, Bayer, YUV, JPEG/PNG."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from speechcal_core.sources.decode import decode_compressed, decode_raw
from speechcal_core.sources.errors import BadFrameError, SourceError

RNG = np.random.default_rng(3)
BGR = RNG.integers(0, 256, (6, 10, 3), dtype=np.uint8)
BGR16 = RNG.integers(0, 65536, (6, 10, 3), dtype=np.uint16)


def padded(pixels: np.ndarray, pad: int) -> tuple[bytes, int]:
    """Rows of ``pixels`` followed by ``pad`` junk bytes each; returns (data, step)."""
    rows = pixels.reshape(pixels.shape[0], -1).view(np.uint8)
    junk = np.full((rows.shape[0], pad), 0xEE, np.uint8)
    out = np.hstack([rows, junk])
    return out.tobytes(), out.shape[1]


@pytest.mark.parametrize("pad", [0, 6])
@pytest.mark.parametrize(
    ("encoding", "pixels", "expected"),
    [
        ("bgr8", BGR, BGR),
        ("8UC3", BGR, BGR),
        ("rgb8", BGR[..., ::-1], BGR),
        ("bgra8", np.dstack([BGR, np.full((6, 10), 7, np.uint8)]), BGR),
        ("rgba8", np.dstack([BGR[..., ::-1], np.full((6, 10), 7, np.uint8)]), BGR),
        ("mono8", BGR[..., 0], BGR[..., 0]),
        ("mono16", BGR16[..., 0], BGR16[..., 0]),
        ("16UC1", BGR16[..., 0], BGR16[..., 0]),
        ("bgr16", BGR16, (BGR16 >> 8).astype(np.uint8)),
        ("rgb16", BGR16[..., ::-1], (BGR16 >> 8).astype(np.uint8)),
        ("rgba16", np.dstack([BGR16[..., ::-1], BGR16[..., :1]]), (BGR16 >> 8).astype(np.uint8)),
    ],
)
def test_raw_layouts_with_and_without_row_padding(encoding, pixels, expected, pad) -> None:
    data, step = padded(np.ascontiguousarray(pixels), pad)
    out = decode_raw(data, encoding, 10, 6, step)
    assert out.dtype == expected.dtype and out.shape == expected.shape
    np.testing.assert_array_equal(out, expected)


def test_big_endian_16_bit_is_swapped() -> None:
    mono = BGR16[..., 0]
    out = decode_raw(mono.astype(">u2").tobytes(), "mono16", 10, 6, 20, is_bigendian=True)
    assert out.dtype == np.uint16
    np.testing.assert_array_equal(out, mono)


@pytest.mark.parametrize("pattern", ["rggb", "bggr", "gbrg", "grbg"])
@pytest.mark.parametrize("bits", [8, 16])
def test_bayer_patterns_debayer_to_the_right_colour(pattern: str, bits: int) -> None:
    colour = {"b": 30, "g": 120, "r": 220}
    mosaic = np.zeros((8, 8), np.uint16 if bits == 16 else np.uint8)
    scale = 256 if bits == 16 else 1
    for k, ch in enumerate(pattern):
        mosaic[k // 2 :: 2, k % 2 :: 2] = colour[ch] * scale
    data, step = padded(mosaic, 4)
    out = decode_raw(data, f"bayer_{pattern}{bits}", 8, 8, step)
    assert out.dtype == np.uint8 and out.shape == (8, 8, 3)
    np.testing.assert_allclose(out[4, 4], [30, 120, 220], atol=2)


@pytest.mark.parametrize(
    ("encoding", "code"), [("uyvy", "UYVY"), ("yuv422", "UYVY"), ("yuyv", "YUYV")]
)
def test_yuv422_packings_convert_to_bgr(encoding: str, code: str) -> None:
    y, u, v = 120, 100, 160
    pair = [u, y, v, y] if code == "UYVY" else [y, u, y, v]
    packed = np.tile(np.array(pair, np.uint8), (4, 4))  # 4 rows, 8 pixels
    out = decode_raw(packed.tobytes(), encoding, 8, 4, 16)
    # BT.601 video range: a swapped U/V or Y position would be far off
    c = 1.164 * (y - 16)
    want = [c + 2.018 * (u - 128), c - 0.813 * (v - 128) - 0.391 * (u - 128), c + 1.596 * (v - 128)]
    np.testing.assert_allclose(out[2, 3], want, atol=3)


def test_unknown_encoding_names_it() -> None:
    with pytest.raises(SourceError, match="unknown image encoding '32FC1'"):
        decode_raw(bytes(240), "32FC1", 10, 6, 40)


def test_short_payload_and_short_step_are_bad_frames() -> None:
    with pytest.raises(BadFrameError, match="payload has 100 bytes"):
        decode_raw(bytes(100), "bgr8", 10, 6, 30)
    with pytest.raises(BadFrameError, match="step 20"):
        decode_raw(bytes(180), "bgr8", 10, 6, 20)


def test_last_row_without_padding_is_accepted() -> None:
    data, step = padded(BGR, 2)
    np.testing.assert_array_equal(decode_raw(data[:-2], "bgr8", 10, 6, step), BGR)


def test_png_16_bit_mono_and_jpeg_colour() -> None:
    mono16 = BGR16[..., 0]
    out = decode_compressed(cv2.imencode(".png", mono16)[1].tobytes())
    assert out.dtype == np.uint16
    np.testing.assert_array_equal(out, mono16)
    jpeg = decode_compressed(cv2.imencode(".jpg", BGR, [cv2.IMWRITE_JPEG_QUALITY, 100])[1])
    assert jpeg.shape == (6, 10, 3) and jpeg.dtype == np.uint8
    bgra = decode_compressed(cv2.imencode(".png", np.dstack([BGR, BGR[..., :1]]))[1])
    np.testing.assert_array_equal(bgra, BGR)


def test_truncated_and_garbage_compressed_payloads_are_bad_frames() -> None:
    data = cv2.imencode(".jpg", BGR)[1].tobytes()
    with pytest.raises(BadFrameError, match="truncated"):
        decode_compressed(data[: len(data) // 2])
    png = cv2.imencode(".png", BGR)[1].tobytes()
    with pytest.raises(BadFrameError, match="truncated"):
        decode_compressed(png[:-20])
    with pytest.raises(BadFrameError, match="cannot be decoded"):
        decode_compressed(b"not an image at all")
    with pytest.raises(BadFrameError, match="empty"):
        decode_compressed(b"")
