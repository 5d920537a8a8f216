#!/usr/bin/env python3
"""Makes grade/tests/data/ssim/: image pairs and their SSIM by scikit-image, the oracle raylab's SSIM
is pinned to (tests/grader_ssim.rs). CI does not run this; it reads what this wrote.

    pip install scikit-image pillow && python3 tools/ssim_expected.py

The pairs are synthetic (seeded numpy) except `cornell_*`, two raylab renders of the glass-ball
Cornell box: with refraction (ior 1.5) and without it (ior 1.0).
"""
from pathlib import Path

import numpy as np
import skimage
from PIL import Image
from skimage.metrics import structural_similarity

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "ssim"


def save(name, array):
    Image.fromarray(np.clip(array, 0, 255).astype(np.uint8), "RGB").save(DATA / name)


def synthetic_pairs():
    rng = np.random.default_rng(20261122)
    h, w = 64, 96
    y, x = np.mgrid[0:h, 0:w]
    gradient = np.stack([x * 255.0 / w, y * 255.0 / h, (x + y) * 127.0 / (w + h) + 64], axis=2)
    save("gradient.png", gradient)
    save("gradient_noise.png", gradient + rng.normal(0, 5, gradient.shape))
    save("gradient_shifted.png", np.roll(gradient, 2, axis=1))
    edges = np.where(((x // 8 + y // 8) % 2)[..., None] == 0, 230.0, 20.0) * np.ones(3)
    save("checker.png", edges)
    save("checker_blur.png", (edges + np.roll(edges, 1, axis=1) + np.roll(edges, 1, axis=0)) / 3)
    save("noise_a.png", rng.uniform(0, 255, (h, w, 3)))
    save("noise_b.png", rng.uniform(0, 255, (h, w, 3)))
    small = rng.uniform(0, 255, (13, 17, 3))
    save("small.png", small)
    save("small_dim.png", small * 0.8)
    return [
        ("gradient.png", "gradient_noise.png"),
        ("gradient.png", "gradient_shifted.png"),
        ("checker.png", "checker_blur.png"),
        ("noise_a.png", "noise_b.png"),
        ("small.png", "small_dim.png"),
        ("gradient.png", "gradient.png"),
    ]


def main():
    DATA.mkdir(parents=True, exist_ok=True)
    pairs = synthetic_pairs()
    if (DATA / "cornell_refract.png").exists():
        pairs.append(("cornell_refract.png", "cornell_no_refraction.png"))
    lines = [f"# SSIM by scikit-image {skimage.__version__}; made by tools/ssim_expected.py\n"]
    for a, b in pairs:
        ia = np.asarray(Image.open(DATA / a).convert("RGB"))
        ib = np.asarray(Image.open(DATA / b).convert("RGB"))
        value = structural_similarity(ia, ib, channel_axis=2, gaussian_weights=True, sigma=1.5,
                                      use_sample_covariance=False, data_range=255)
        lines.append(f'\n[[pair]]\na = "{a}"\nb = "{b}"\nssim = {float(value)!r}\n')
    (DATA / "expected.toml").write_text("".join(lines))


if __name__ == "__main__":
    main()
