//! How alike two texts of one region are, and how much likelier that is for a copy than for
//! independent work.
//!
//! **Similarity** of texts `a` and `b` of one region: the weighted Dice coefficient of their
//! fingerprints, `S = 2 Σ_{f ∈ a ∩ b} w_f / (Σ_a w_f + Σ_b w_f)`, in `[0, 1]`, 1 only for the same
//! fingerprints. A fingerprint's weight is its rarity among the distinct texts of that region at
//! hand (class and references), `w_f = ln(1 + N / n_f)` for `n_f` of the `N` distinct texts
//! holding it: the textbook core every student writes weighs little, a shared oddity much, and
//! copies of one text, counted once, do not make their own fingerprints look common. Fingerprints
//! of the starter's stub never count (a student who left its `let _ = ...` line shares nothing by
//! it). Dice, not containment in the smaller text: on the test set, containment put eight pairs of
//! independent regions at 1 (a short text inside a long one); padding a copy with unused code,
//! the reason to prefer containment, is undone before (`normalise`).
//!
//! **How likely, copied or not.** Independent solutions of a short function are bound to be alike
//! (fifteen lines of Möller-Trumbore leave little choice; the test set has independent pairs at
//! `S = 1`), so `S` alone says little. For each region, the likelihood ratio
//! `Λ(S) = P(S' ≈ S | copied) / P(S' ≈ S | independent)`, "≈" meaning within [`BANDWIDTH`]:
//! - copied: after normalising, a copy is the same text; a copier who also edits a line or two
//!   lands a little lower, so `S` is taken uniform on `[1 − δ, 1]`, `δ` = [`COPY_SPREAD`];
//! - independent: counted among the pairs of independent implementations of that region (the test
//!   set, `grade/tests/similarity/`), half a pair added, `(k + ½) / (n + 1)`, so no region is
//!   ever certain.
//!
//! A region less alike than copies are has `Λ = 0`; one alike as only copies are, a large `Λ`.
//!
//! **A pair's score** is the log-likelihood ratio of "each region copied with probability `π`"
//! over "independent": `Σ_r ln(1 − π + π Λ_r)` over the regions both wrote, `π` = [`PRIOR`]. A region nothing like a copy costs `ln(1 − π)`, a little; each
//! region alike as copies are adds as much as its likeness is rare among independent pairs.

use std::collections::{BTreeSet, HashMap, HashSet};

use crate::instructor::similarity::winnow::Print;

/// `δ`: a copied region's similarity is taken uniform on `[1 − δ, 1]`. A fifth: a copier may
/// rewrite a line in five and still be a copier. Compared with a tenth and three tenths while
/// the engine was written, looking at both halves of the test set (docs/GRADING.md says so).
pub const COPY_SPREAD: f64 = 0.2;

/// How near two similarities are to count as alike: half of [`COPY_SPREAD`], so a copy's whole
/// range is two bandwidths.
pub const BANDWIDTH: f64 = 0.1;

/// The fingerprint hashes of each text of one region, the stub's removed.
pub struct RegionTexts<'a> {
    /// Each text's fingerprints.
    pub prints: Vec<&'a [Print]>,
    /// The hashes of the starter's stub for this region.
    pub stub: HashSet<u64>,
}

/// The weights of one region's fingerprints: `ln(1 + N / n_f)`.
pub struct Weights {
    weight: HashMap<u64, f64>,
    /// The weight of a fingerprint one text alone holds, `ln(1 + N)`.
    rarest: f64,
    stub: HashSet<u64>,
}

impl Weights {
    /// The weights over the distinct texts of the region at hand.
    pub fn of(texts: &RegionTexts) -> Weights {
        let distinct: BTreeSet<BTreeSet<u64>> =
            texts.prints.iter().map(|prints| prints.iter().map(|p| p.hash).collect()).collect();
        let mut held: HashMap<u64, usize> = HashMap::new();
        for hash in distinct.iter().flatten() {
            *held.entry(*hash).or_default() += 1;
        }
        let n = distinct.len().max(1) as f64;
        let weight = held.into_iter().map(|(hash, count)| (hash, (1.0 + n / count as f64).ln())).collect();
        Weights { weight, rarest: (1.0 + n).ln(), stub: texts.stub.clone() }
    }

    /// The similarity `S` of two texts' fingerprints; 0 when neither has any of its own. Summed
    /// in hash order, so the same texts give the same bits.
    pub fn similarity(&self, a: &[Print], b: &[Print]) -> f64 {
        let set = |prints: &[Print]| -> BTreeSet<u64> {
            prints.iter().map(|p| p.hash).filter(|h| !self.stub.contains(h)).collect()
        };
        let (a, b) = (set(a), set(b));
        // A fingerprint not among the texts the weights were made from is as rare as can be.
        let w = |h: &u64| self.weight.get(h).copied().unwrap_or(self.rarest);
        let both = a.iter().map(w).sum::<f64>() + b.iter().map(w).sum::<f64>();
        if both <= 0.0 {
            return 0.0;
        }
        2.0 * a.intersection(&b).map(w).sum::<f64>() / both
    }
}

/// What independent pairs of one region reach: their similarities, in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Null {
    sorted: Vec<f64>,
}

impl Null {
    /// The null of the similarities `s` of independent pairs.
    pub fn of(s: &[f64]) -> Null {
        let mut sorted = s.to_vec();
        sorted.sort_by(f64::total_cmp);
        Null { sorted }
    }

    /// `Λ(s)`: the chance of a similarity within [`BANDWIDTH`] of `s` for a copy over that for
    /// an independent pair.
    pub fn likelihood_ratio(&self, s: f64) -> f64 {
        // The window keeps its width at the ends of [0, 1], so a copy at 1 is no less likely
        // than an edited one at 0.9.
        let lo = (s - BANDWIDTH).clamp(0.0, 1.0 - 2.0 * BANDWIDTH);
        let hi = lo + 2.0 * BANDWIDTH;
        let copied = (hi - lo.max(1.0 - COPY_SPREAD)).max(0.0) / COPY_SPREAD;
        let near = self.sorted.partition_point(|&x| x <= hi) - self.sorted.partition_point(|&x| x < lo);
        copied / ((near as f64 + 0.5) / (self.sorted.len() as f64 + 1.0))
    }

    /// How many independent pairs it holds.
    pub fn pairs(&self) -> usize {
        self.sorted.len()
    }
}

/// `π`: the chance that a region of a pair is copied, a priori: one in twelve (the eleven regions
/// of checkpoints 2 to 7, and one more, so no region is certain). The same for every pair, so a
/// region's term means the same whatever else a pair wrote (the threshold is measured on pairs
/// that wrote all eleven).
pub const PRIOR: f64 = 1.0 / 12.0;

/// A pair's score from its regions' likelihood ratios: `Σ ln(1 − π + π Λ)`; 0 for no region.
pub fn copy_score(ratios: &[f64]) -> f64 {
    ratios.iter().map(|lr| (1.0 - PRIOR + PRIOR * lr).ln()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prints(hashes: &[u64]) -> Vec<Print> {
        hashes.iter().map(|&hash| Print { hash, lines: 1..=1 }).collect()
    }

    #[test]
    fn similarity_of_shared_rare_prints_outweighs_shared_common_ones() {
        // Four texts: prints 1 and 2 everyone has (the textbook core), 10.. their own.
        let texts = [
            prints(&[1, 2, 10, 11]),
            prints(&[1, 2, 20, 21]),
            prints(&[1, 2, 30, 10]),
            prints(&[1, 2, 40, 41]),
        ];
        let weights = Weights::of(&RegionTexts {
            prints: texts.iter().map(Vec::as_slice).collect(),
            stub: HashSet::new(),
        });
        let core_only = weights.similarity(&texts[1], &texts[3]);
        let core_and_rare = weights.similarity(&texts[0], &texts[2]);
        assert!(core_only > 0.0 && core_and_rare > core_only, "{core_only} {core_and_rare}");
        assert_eq!(weights.similarity(&texts[0], &texts[0]), 1.0);
    }

    #[test]
    fn similarity_never_counts_the_stub_and_is_one_only_for_the_same_prints() {
        let stub: HashSet<u64> = [7].into();
        let texts = [prints(&[7, 1]), prints(&[7, 2])];
        let weights = Weights::of(&RegionTexts { prints: texts.iter().map(Vec::as_slice).collect(), stub });
        assert_eq!(weights.similarity(&texts[0], &texts[1]), 0.0, "only the stub's line is shared");
        assert_eq!(weights.similarity(&prints(&[7]), &prints(&[7])), 0.0, "a stub is nobody's text");
        // A short text inside a long one is not the same text: Dice, 2 * 1 / (1 + 4) of equal weights.
        let inside = weights.similarity(&prints(&[1]), &prints(&[1, 3, 4, 5]));
        assert!((inside - 0.4).abs() < 1e-12, "{inside}");
    }

    #[test]
    fn similarity_likelihood_ratio_compares_a_copy_s_chance_with_independent_pairs() {
        // Four independent pairs, one of them at 1.
        let null = Null::of(&[0.2, 0.4, 0.3, 1.0]);
        // At 1 the window is [0.8, 1]: all of a copy's range; independent pairs 1 of 4,
        // (1 + 1/2) / 5.
        assert!((null.likelihood_ratio(1.0) - 1.0 / (1.5 / 5.0)).abs() < 1e-12);
        assert_eq!(null.likelihood_ratio(0.9), null.likelihood_ratio(1.0), "the window keeps its width");
        // At 0.75: [0.65, 0.85] holds a quarter of the copy's range; no pair near.
        assert!((null.likelihood_ratio(0.75) - 0.25 / (0.5 / 5.0)).abs() < 1e-12);
        // Far from 1: no copy is that unlike.
        assert_eq!(null.likelihood_ratio(0.5), 0.0);
        // Never certain, even with no pairs at all.
        assert!(Null::of(&[]).likelihood_ratio(1.0).is_finite());
    }

    #[test]
    fn similarity_pair_score_counts_unusual_regions_and_barely_the_others() {
        let usual = [0.0; 11];
        assert!(copy_score(&usual) < 0.0 && copy_score(&usual) > -1.0, "{}", copy_score(&usual));
        let one = copy_score(&[[20.0].as_slice(), &[0.0; 10]].concat());
        let four = copy_score(&[[20.0; 4].as_slice(), &[0.0; 7]].concat());
        assert!(one > 0.0 && four > 4.0 * one, "{one} {four}");
        // One region: ln(11/12 + 1/12 * 13) = ln 2.
        assert!((copy_score(&[13.0]) - 2.0f64.ln()).abs() < 1e-12);
        assert!(copy_score(&[0.0]).is_finite(), "one unlike region is not minus infinity");
        assert_eq!(copy_score(&[]), 0.0);
    }
}
