"""8-bit sRGB images kept sRGB-encoded and decoded after interpolation (core/materials/textures.SrgbImage), as
Cycles samples them: the bilinear lookup, its gradient (image bump), the mean texel (light power) and the node
program's lookups agree with decoding the interpolated sRGB values; crossing to a worker process keeps the kind."""
import pickle

import numpy as np

from restir_engine.core.materials.nodes.ops_texture import sample_image
from restir_engine.core.materials.textures import (SrgbImage, SrgbLuminanceImage, decoded, gradient, mean_color,
                                                   sample, sample_bilinear, srgb_to_linear)

LUM = np.array([0.2126, 0.7152, 0.0722])


def _image(kind=SrgbImage, n=6, seed=3):
    rng = np.random.default_rng(seed)
    return (np.rint(rng.uniform(0, 1, (n, n, 3)) * 255) / 255).astype(np.float32).view(kind)


def _exact_decode(s):
    s = np.asarray(s, np.float64)
    return np.where(s < 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)


def test_lookups_interpolate_srgb_values_then_decode():
    img = _image()
    rng = np.random.default_rng(4)
    uv = rng.uniform(-1, 2, (500, 2)).astype(np.float32)
    raw = sample_bilinear(np.asarray(img), uv)
    want = _exact_decode(raw)
    np.testing.assert_allclose(sample(img, uv), want, rtol=2e-6, atol=1e-7)
    # decoding first (linear interpolation of decoded texels) is brighter where texels differ: not what is returned
    early = sample_bilinear(np.asarray(_exact_decode(np.asarray(img)), np.float32), uv)
    assert (early - want).mean() > 1e-3
    for interp in ("Linear", "Cubic", "Closest"):
        got = sample_image(img, uv[:, 0], uv[:, 1], interp, "REPEAT")
        np.testing.assert_allclose(got, _exact_decode(sample_image(np.asarray(img), uv[:, 0], uv[:, 1], interp,
                                                                   "REPEAT")), rtol=2e-6, atol=1e-7)
    lum = img.view(SrgbLuminanceImage)
    np.testing.assert_allclose(sample(lum, uv), np.repeat((want @ LUM)[:, None], 3, axis=1), rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(srgb_to_linear(np.array([-0.5, 0.0, 0.04, 0.5, 1.0])),
                               [0.0, 0.0, 0.04 / 12.92, _exact_decode(0.5), 1.0], rtol=1e-6)


def test_gradient_is_the_derivative_of_the_decoded_lookup():
    rng = np.random.default_rng(5)
    uv = rng.uniform(0.05, 0.95, (200, 2))
    eps = 1e-4
    for kind in (SrgbImage, SrgbLuminanceImage):
        img = _image(kind)
        g = gradient(img, uv.astype(np.float32))
        for axis in (0, 1):
            d = np.zeros(2)
            d[axis] = eps
            fd = (sample(img, (uv + d).astype(np.float64))[:, 0].astype(np.float64)
                  - sample(img, (uv - d).astype(np.float64))[:, 0]) / (2 * eps)
            np.testing.assert_allclose(g[:, axis], fd, rtol=5e-3, atol=5e-3)


def test_mean_texel_and_pickling():
    img = _image()
    np.testing.assert_allclose(mean_color(img), _exact_decode(np.asarray(img)).reshape(-1, 3).mean(0), rtol=1e-5)
    back = pickle.loads(pickle.dumps(img.view(SrgbLuminanceImage), protocol=5))
    assert type(back) is SrgbLuminanceImage and np.array_equal(np.asarray(back), np.asarray(img))
    plain, texels = np.asarray(img), np.asarray(img)[0]
    assert decoded(plain, texels) is texels  # other images are returned as they are stored
