//! How alike two texts of one region are, and how unusual that is for the region.
//!
//! **Similarity** of texts `a` and `b` of one region: the weight of the fingerprints they share
//! over the weight of the smaller text's, `S = Σ_{f ∈ a ∩ b} w_f / min(Σ_a w_f, Σ_b w_f)`, in
//! `[0, 1]`. A fingerprint's weight is its rarity among all the texts of that region at hand
//! (class and references), `w_f = ln(1 + N / n_f)` for `n_f` of the `N` texts holding it: the
//! textbook core every student writes weighs little, a shared oddity much. Fingerprints of the
//! starter's stub never count (a student who left its `let _ = ...` line shares nothing by it).
//! The smaller text is the yardstick so that padding one copy with new code does not hide it.
//!
//! **Unusualness**: independent solutions of a short function are bound to be alike (fifteen lines
//! of Möller-Trumbore leave little choice), so `S` alone says little. Each region's `S` is turned
//! into standard scores against the pairs of independent implementations of that region
//! (the test set, `grade/tests/similarity/`), `z = (S − mean) / sd`; the sd is at least one
//! fingerprint's share of a median text (`1 / median prints`), the measure's own resolution, so a
//! region that every independent pair shares nothing of does not turn one shared run into a
//! flag. A pair's score combines its regions by Stouffer's method, `Z = Σ z / sqrt(R)` over the `R`
//! regions both wrote: unusual likeness in many regions adds up, the same in one region counts
//! for less.

use std::collections::{HashMap, HashSet};

use crate::instructor::similarity::winnow::Print;

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
    /// The weights over every text of the region at hand.
    pub fn of(texts: &RegionTexts) -> Weights {
        let mut held: HashMap<u64, usize> = HashMap::new();
        for prints in &texts.prints {
            let distinct: HashSet<u64> = prints.iter().map(|p| p.hash).collect();
            for hash in distinct {
                *held.entry(hash).or_default() += 1;
            }
        }
        let n = texts.prints.len().max(1) as f64;
        let weight = held.into_iter().map(|(hash, count)| (hash, (1.0 + n / count as f64).ln())).collect();
        Weights { weight, rarest: (1.0 + n).ln(), stub: texts.stub.clone() }
    }

    /// The similarity `S` of two texts' fingerprints; 0 when either has none of its own.
    pub fn similarity(&self, a: &[Print], b: &[Print]) -> f64 {
        let set = |prints: &[Print]| -> HashSet<u64> {
            prints.iter().map(|p| p.hash).filter(|h| !self.stub.contains(h)).collect()
        };
        let (a, b) = (set(a), set(b));
        // A fingerprint not among the texts the weights were made from is as rare as can be.
        let w = |h: &u64| self.weight.get(h).copied().unwrap_or(self.rarest);
        let total = |s: &HashSet<u64>| s.iter().map(w).sum::<f64>();
        let smaller = total(&a).min(total(&b));
        if smaller <= 0.0 {
            return 0.0;
        }
        a.intersection(&b).map(w).sum::<f64>() / smaller
    }
}

/// What independent pairs of one region reach: the mean and sd that a pair's `S` is scored by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Null {
    /// The mean `S` of independent pairs.
    pub mean: f64,
    /// Their sd, at least the measure's resolution.
    pub sd: f64,
}

impl Null {
    /// The null of the similarities `s` of independent pairs, whose texts have a median of
    /// `median_prints` fingerprints.
    pub fn of(s: &[f64], median_prints: f64) -> Null {
        let n = s.len().max(1) as f64;
        let mean = s.iter().sum::<f64>() / n;
        let var = s.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        Null { mean, sd: var.sqrt().max(1.0 / median_prints.max(1.0)) }
    }

    /// The standard score of a similarity.
    pub fn z(&self, s: f64) -> f64 {
        (s - self.mean) / self.sd
    }
}

/// Stouffer's combination of the regions' standard scores: `Σ z / sqrt(R)`; 0 for no region.
pub fn stouffer(z: &[f64]) -> f64 {
    if z.is_empty() {
        0.0
    } else {
        z.iter().sum::<f64>() / (z.len() as f64).sqrt()
    }
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
    fn similarity_never_counts_the_stub_and_uses_the_smaller_text() {
        let stub: HashSet<u64> = [7].into();
        let texts = [prints(&[7, 1]), prints(&[7, 2])];
        let weights = Weights::of(&RegionTexts { prints: texts.iter().map(Vec::as_slice).collect(), stub });
        assert_eq!(weights.similarity(&texts[0], &texts[1]), 0.0, "only the stub's line is shared");
        assert_eq!(weights.similarity(&prints(&[7]), &prints(&[7])), 0.0, "a stub is nobody's text");
        // A copy padded with new code is still wholly contained.
        assert_eq!(weights.similarity(&prints(&[1]), &prints(&[1, 3, 4, 5])), 1.0);
    }

    #[test]
    fn similarity_scores_against_independent_pairs_with_a_floor_on_their_spread() {
        let null = Null::of(&[0.2, 0.4, 0.3, 0.3], 100.0);
        assert!((null.mean - 0.3).abs() < 1e-12);
        assert!((null.sd - (0.02f64 / 3.0).sqrt()).abs() < 1e-12);
        // Independent pairs that share nothing: the spread is one print in ten.
        assert_eq!(Null::of(&[0.0, 0.0], 10.0).sd, 0.1);
        assert!((stouffer(&[2.0, 2.0, 2.0, 2.0]) - 4.0).abs() < 1e-12);
        assert_eq!(stouffer(&[]), 0.0);
    }
}
