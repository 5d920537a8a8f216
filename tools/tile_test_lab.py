"""The tile test's spread statistics on many correct renders: why the spread is a rank test.

Run by hand, not in CI (needs numpy and scipy: `pip install numpy scipy`), from the repository
root after `cargo build --release --bin render`:

    python tools/tile_test_lab.py scenes/glass_light.toml --renders 400

It renders the scene `--renders` times at its graded spp with seeds no grader uses
(5 * 2^42 + k), takes every render's 16 x 16 tile means, and then, drawing disjoint groups of 16
("a submission") and 64 ("the solution") from those correct renders, counts how often each spread
test fails a correct submission at the grader's Sidak level (alpha = 0.001 over tiles x 3 x 2),
and how often it catches renders whose deviations are scaled by 2, 2.83 and 4 (a correct but
noisier renderer). It prints the tiles' largest excess kurtosis too. docs/GRADING.md quotes its
figures for glass_light and lights_mixed.
"""

import argparse
import pathlib
import subprocess
import tempfile

import numpy as np
from scipy import stats

TILE, SUBMISSION, SOLUTION, ALPHA = 16, 16, 64, 1e-3


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(height, width, 3)[::-1]  # PFM rows run bottom to top


def tile_means(renders):
    n, h, w, _ = renders.shape
    return renders.reshape(n, h // TILE, TILE, w // TILE, TILE, 3).mean(axis=(2, 4)).reshape(n, -1, 3)


def render_all(scene, count):
    with tempfile.TemporaryDirectory() as tmp:
        films = []
        for k in range(count):
            png, pfm = pathlib.Path(tmp, "r.png"), pathlib.Path(tmp, "r.pfm")
            seed = 5 * 2**42 + k
            subprocess.run(["target/release/render", scene, "-o", png, "--pfm", pfm, "--seed", str(seed)],
                           check=True, capture_output=True)
            films.append(read_pfm(pfm).astype(np.float64))
    return tile_means(np.array(films))


def f_test(sub, sol, _centre):
    va, vb = sub.var(axis=0, ddof=1), sol.var(axis=0, ddof=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(vb > 0, va / vb, 1.0)
    return stats.f.sf(ratio, len(sub) - 1, len(sol) - 1)


def rank_test(sub, sol, centre):
    a, b = np.abs(sub - centre).reshape(len(sub), -1), np.abs(sol - centre).reshape(len(sol), -1)
    p = np.ones(a.shape[1])
    varies = b.max(axis=0) > 0
    p[varies] = stats.mannwhitneyu(a[:, varies], b[:, varies], alternative="greater", axis=0).pvalue
    return p.reshape(sub.shape[1:])


def rates(means, test, scale, trials, rng):
    level = 1 - (1 - ALPHA) ** (1 / (means.shape[1] * 3 * 2))
    centre = means.mean(axis=0)
    images = tiles = 0.0
    for _ in range(trials):
        order = rng.permutation(len(means))
        sub, sol = means[order[:SUBMISSION]], means[order[SUBMISSION:SUBMISSION + SOLUTION]]
        sub = centre + (sub - centre) * scale
        failed = (test(sub, sol, centre) < level).any(axis=1)
        images += failed.any()
        tiles += failed.mean()
    return images / trials, tiles / trials


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--renders", type=int, default=400)
    args = parser.parse_args()
    means = render_all(args.scene, args.renders)
    print(f"{args.scene}: {args.renders} renders; largest excess kurtosis of a tile's means:"
          f" {np.nanmax(stats.kurtosis(means, axis=0)):.1f}")
    rng = np.random.default_rng(1)
    for name, test in [("F-test", f_test), ("rank test", rank_test)]:
        null = rates(means, test, 1.0, 2000, rng)
        power = [rates(means, test, s, 300, rng) for s in (2.0, 2.83, 4.0)]
        print(f"{name:>9}: correct submissions failing {null[0]:.2%}; noisier by 2 / 2.83 / 4:"
              f" images caught {' / '.join(f'{p[0]:.0%}' for p in power)},"
              f" tiles caught {' / '.join(f'{p[1]:.1%}' for p in power)}")


if __name__ == "__main__":
    main()
