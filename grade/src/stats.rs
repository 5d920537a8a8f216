//! The statistics only the grader uses, beside the renderer's (`raylab_base::stats`, which the
//! checkpoints' own tests use too): the tile test's exact rank test and Šidák's level
//! ([`crate::noisy`]), and the binomial bounds of the calibration of that test
//! ([`crate::instructor::calibrate`]).
//!
//! **Maths.** Testing `m` things at once with a family-wise error rate `α`, each is tested at
//! Šidák's `1 − (1 − α)^(1/m)`.
//!
//! A binomial count `X` of `n` trials with rate `p` has `P(X ≥ x) = I_p(x, n − x + 1)`; the
//! Clopper-Pearson interval for `p` after `x` of `n` is the pair of rates at which `x` lies in
//! either tail with probability `(1 − c) / 2` (the exact, conservative interval), found here by
//! bisection on that identity.
//!
//! The Mann-Whitney statistic `U = #{(i, j) : a_i > b_j}` of two samples of sizes `m` and `n` drawn
//! from one continuous distribution has a distribution that does not depend on that distribution:
//! the largest of the `m + n` values is one of the `a` with probability `m / (m + n)`, and then
//! exceeds every `b`, so `P_{m,n}(u) = m/(m+n) · P_{m−1,n}(u − n) + n/(m+n) · P_{m,n−1}(u)`, with
//! `P_{0,n} = P_{m,0} = [u = 0]` (the recursion of Mann and Whitney, 1947, in probabilities, so
//! every term is positive and nothing cancels). Its exact tail needs no normality, which is why
//! the grader compares the spreads of noisy renders with it: their tile means can be far from
//! normal (a rare bright path), where an F-test of variances fails correct renders.

use raylab_base::stats::incomplete_beta;

/// The exact null distribution of the Mann-Whitney statistic for samples of sizes `m` and `n`
/// (module docs), kept as its upper tail: build it once, test many pairs of samples.
#[derive(Clone, Debug)]
pub struct RankTest {
    m: usize,
    n: usize,
    /// `tail[u] = P(U ≥ u)`, for `u` in `0 ..= m·n`.
    tail: Vec<f64>,
}

impl RankTest {
    /// The distribution for samples of `m` and `n` values.
    pub fn new(m: usize, n: usize) -> Self {
        let top = m * n;
        // rows[j] is P_{i,j} for the current i, as a vector over u.
        let mut rows: Vec<Vec<f64>> = (0..=n).map(|_| point_mass(top)).collect();
        for i in 1..=m {
            let mut next = vec![point_mass(top)];
            for j in 1..=n {
                let (a, b) = (i as f64 / (i + j) as f64, j as f64 / (i + j) as f64);
                let mut p: Vec<f64> = next[j - 1].iter().map(|q| b * q).collect();
                for (u, q) in rows[j].iter().enumerate().take(top + 1 - j) {
                    p[u + j] += a * q;
                }
                next.push(p);
            }
            rows = next;
        }
        let mut tail = rows.pop().unwrap_or_else(|| point_mass(top));
        for u in (0..top).rev() {
            tail[u] += tail[u + 1];
        }
        Self { m, n, tail }
    }

    /// `P(U ≥ u)` for the `U` of `a` (the `m` values) against `b` (the `n`): how likely a sample
    /// from `b`'s distribution lies this far above `b`. Ties count against `a` (not as a half),
    /// which can only raise the p-value.
    pub fn p_greater(&self, a: &[f64], b: &[f64]) -> f64 {
        assert!(a.len() == self.m && b.len() == self.n, "built for {} and {} values", self.m, self.n);
        let mut sorted = b.to_vec();
        sorted.sort_by(f64::total_cmp);
        let u: usize = a.iter().map(|x| sorted.partition_point(|y| y < x)).sum();
        self.tail[u]
    }
}

/// The distribution of a statistic that is 0 for certain, over `0 ..= top`.
fn point_mass(top: usize) -> Vec<f64> {
    let mut p = vec![0.0; top + 1];
    p[0] = 1.0;
    p
}

/// Šidák's per-test level for `tests` tests with a family-wise error rate `alpha`.
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests as f64)
}

/// `P(X ≥ x)` for a binomial count `X` of `n` trials with rate `p`.
pub fn binomial_at_least(x: u64, n: u64, p: f64) -> f64 {
    match x {
        0 => 1.0,
        x if x > n => 0.0,
        x => incomplete_beta(x as f64, (n - x + 1) as f64, p),
    }
}

/// The Clopper-Pearson interval of confidence `confidence` (e.g. 0.95) for a binomial rate after
/// `x` successes in `n` trials.
pub fn clopper_pearson(x: u64, n: u64, confidence: f64) -> (f64, f64) {
    let tail = (1.0 - confidence) / 2.0;
    // P(X ≥ x) grows with p; P(X ≤ x) = 1 − P(X ≥ x + 1) falls with it.
    let lower = if x == 0 { 0.0 } else { bisect(|p| binomial_at_least(x, n, p) - tail) };
    let upper = if x == n { 1.0 } else { bisect(|p| tail - (1.0 - binomial_at_least(x + 1, n, p))) };
    (lower, upper)
}

/// The root in `[0, 1]` of a function rising through zero once.
fn bisect(f: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_base::stats::ln_gamma;

    fn close(got: f64, want: f64, tolerance: f64) {
        assert!((got - want).abs() <= tolerance, "{got} vs {want}");
    }

    /// A small case counted by hand, a larger one by enumerating every order of the values, and
    /// the extremes and symmetry of the grader's case (16 renders against 64).
    #[test]
    fn the_rank_test_has_the_exact_distribution() {
        // m = 2, n = 2: the 6 orders of aabb give U = 4 (aabb above), 3, 2, 2, 1, 0.
        let test = RankTest::new(2, 2);
        for (u, want) in [(0, 1.0), (1, 5.0 / 6.0), (2, 4.0 / 6.0), (3, 2.0 / 6.0), (4, 1.0 / 6.0)] {
            close(test.tail[u], want, 1e-15);
        }
        // m = 4, n = 7: each of the C(11, 4) = 330 choices of the a's ranks (bits of a mask, rank
        // 0 lowest) is equally likely; U counts the b's below each a.
        let (m, n) = (4, 7);
        let mut counts = vec![0u32; m * n + 1];
        for mask in (0u32..1 << (m + n)).filter(|mask| mask.count_ones() == m as u32) {
            let u: u32 = (0..m + n)
                .filter(|r| mask & 1 << r != 0)
                .map(|r| r as u32 - (mask & ((1 << r) - 1)).count_ones())
                .sum();
            counts[u as usize] += 1;
        }
        let test = RankTest::new(m, n);
        for u in 0..=m * n {
            close(test.tail[u], counts[u..].iter().sum::<u32>() as f64 / 330.0, 1e-14);
        }
        close(RankTest::new(3, 5).p_greater(&[7.0, 8.0, 9.0], &[1.0, 2.0, 3.0, 4.0, 5.0]), 1.0 / 56.0, 1e-15);
        // Ties count against a: a sample equal to b passes for certain.
        close(RankTest::new(2, 3).p_greater(&[1.0, 1.0], &[1.0, 1.0, 1.0]), 1.0, 0.0);
        let test = RankTest::new(16, 64);
        // Symmetry about mn/2 = 512: P(U ≥ 513) + P(U ≥ 512) = P(U > 512) + P(U ≥ 512) = 1.
        close(test.tail[513] + test.tail[512], 1.0, 1e-12);
        // All 16 above all 64: 1 / C(80, 16).
        close(test.tail[16 * 64] * 26_958_221_130_508_525.0, 1.0, 1e-9);
    }

    /// Šidák: one test keeps α; m tests at the per-test level fail together with probability α.
    #[test]
    fn sidak_levels_keep_the_family_wise_error_rate() {
        close(sidak(0.01, 1), 0.01, 1e-15);
        let per_test = sidak(0.01, 256);
        close(1.0 - (1.0 - per_test).powi(256), 0.01, 1e-12);
    }

    /// The binomial tail against direct sums, and Clopper-Pearson against its closed forms for
    /// 0 of n (`1 − (tail)^(1/n)`) and n of n, and a published value (1 of 20 at 95%: 0.0013 to
    /// 0.2487, Clopper and Pearson's tables as reprinted in Newcombe 1998).
    #[test]
    fn binomial_tails_and_clopper_pearson_intervals_match_their_closed_forms() {
        let pmf = |k: u64, n: u64, p: f64| {
            (ln_gamma(n as f64 + 1.0) - ln_gamma(k as f64 + 1.0) - ln_gamma((n - k) as f64 + 1.0)).exp()
                * p.powi(k as i32)
                * (1.0 - p).powi((n - k) as i32)
        };
        for (x, n, p) in [(3, 20, 0.1), (1, 5, 0.5), (10, 12, 0.7)] {
            close(binomial_at_least(x, n, p), (x..=n).map(|k| pmf(k, n, p)).sum(), 1e-12);
        }
        let (lo, hi) = clopper_pearson(0, 20, 0.95);
        close(lo, 0.0, 0.0);
        close(hi, 1.0 - 0.025f64.powf(1.0 / 20.0), 1e-12);
        let (lo, hi) = clopper_pearson(20, 20, 0.95);
        close(lo, 0.025f64.powf(1.0 / 20.0), 1e-12);
        close(hi, 1.0, 0.0);
        let (lo, hi) = clopper_pearson(1, 20, 0.95);
        close(lo, 0.0013, 5e-5);
        close(hi, 0.2487, 5e-5);
    }
}
