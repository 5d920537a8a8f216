//! Winnowing (Schleimer, Wilkerson and Aiken, SIGMOD 2003, the method of MOSS and Dolos): a
//! region's fingerprints are a few hashes of its `K`-token runs, chosen so that any shared run of
//! at least `K + W - 1` tokens gives the two regions a fingerprint in common.
//!
//! Every run of `K` consecutive normalised tokens is hashed; in each window of `W` consecutive
//! hashes the smallest is kept (the rightmost of equals). Two texts that share a run of `K + W - 1`
//! tokens share a whole window, so they keep the same smallest hash there: a guarantee, not a
//! chance. A region shorter than `K` tokens is one fingerprint of all of them.

use std::ops::RangeInclusive;

use crate::instructor::similarity::normalise::Token;
use crate::reference::fnv1a64;

/// Tokens per hashed run. Eight normalised tokens are a short expression (`$v . dot ( $v ) < 0 ;`):
/// fewer would match every region's idioms, more would miss a copied line whose neighbours changed.
pub const K: usize = 8;

/// Hashes per window: any shared run of `K + W - 1 = 11` tokens is found.
pub const W: usize = 4;

/// One kept hash and the region lines its tokens span.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Print {
    /// The hash of the run of tokens.
    pub hash: u64,
    /// The first and last region line of the run.
    pub lines: RangeInclusive<usize>,
}

/// The fingerprints of `tokens`, in order, each kept position once.
pub fn winnow(tokens: &[Token]) -> Vec<Print> {
    if tokens.is_empty() {
        return Vec::new();
    }
    let k = K.min(tokens.len());
    let runs: Vec<Print> = tokens.windows(k).map(run_print).collect();
    let w = W.min(runs.len());
    let mut kept: Vec<usize> = Vec::new();
    for start in 0..=runs.len() - w {
        let smallest =
            (start..start + w).rev().min_by_key(|&i| runs[i].hash).expect("a window is never empty");
        if kept.last() != Some(&smallest) {
            kept.push(smallest);
        }
    }
    kept.into_iter().map(|i| runs[i].clone()).collect()
}

/// The hash of one run of tokens and the lines it spans.
fn run_print(run: &[Token]) -> Print {
    let joined: Vec<u8> = run.iter().flat_map(|t| t.text.bytes().chain([0])).collect();
    let first = run.iter().map(|t| t.line).min().expect("a run is never empty");
    let last = run.iter().map(|t| t.line).max().expect("a run is never empty");
    Print { hash: fnv1a64(&joined), lines: first..=last }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(text: &str) -> Vec<Token> {
        text.split_whitespace()
            .enumerate()
            .map(|(i, t)| Token { text: t.to_string(), line: i / 5 + 1 })
            .collect()
    }

    #[test]
    fn similarity_winnowing_finds_every_shared_run_of_k_plus_w_minus_1_tokens() {
        // Two texts of different tokens around one shared run of exactly K + W - 1 tokens.
        let shared: Vec<String> = (0..K + W - 1).map(|i| format!("s{i}")).collect();
        for before in 0..6 {
            let a = format!(
                "{} {} a1 a2 a3",
                (0..before).map(|i| format!("x{i}")).collect::<Vec<_>>().join(" "),
                shared.join(" ")
            );
            let b = format!("b1 b2 {} y1 y2 y3 y4", shared.join(" "));
            let pa: Vec<u64> = winnow(&tokens(&a)).iter().map(|p| p.hash).collect();
            let pb: Vec<u64> = winnow(&tokens(&b)).iter().map(|p| p.hash).collect();
            assert!(pa.iter().any(|h| pb.contains(h)), "shared run after {before} tokens missed");
        }
        // Nothing shared, nothing in common.
        let pa: Vec<u64> = winnow(&tokens("a b c d e f g h i j k l")).iter().map(|p| p.hash).collect();
        let pb: Vec<u64> = winnow(&tokens("m n o p q r s t u v w x")).iter().map(|p| p.hash).collect();
        assert!(pa.iter().all(|h| !pb.contains(h)));
    }

    #[test]
    fn similarity_winnowing_keeps_fewer_prints_than_runs_and_one_for_a_short_region() {
        let long = tokens(&(0..200).map(|i| format!("t{i}")).collect::<Vec<_>>().join(" "));
        let prints = winnow(&long);
        // The expected density of winnowing is 2 / (W + 1) of the runs.
        let runs = long.len() - K + 1;
        assert!(prints.len() < runs && prints.len() * (W + 1) > runs, "{} of {runs}", prints.len());
        assert_eq!(winnow(&tokens("a b c")).len(), 1);
        assert!(winnow(&[]).is_empty());
        assert_eq!(winnow(&tokens("a b c d e f g h i j k"))[0].lines, 1..=2);
    }
}
