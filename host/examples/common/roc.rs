//! The area under a signal's ROC curve, as the lost-flag studies compute it.
#![allow(dead_code)] // each example uses part of it

/// The probability that a positive's signal exceeds a negative's (ties count half): the
/// area under the ROC curve, by the Mann–Whitney rank sum. `NaN` when either side is empty.
pub fn auc(positive: &[f64], negative: &[f64]) -> f64 {
    if positive.is_empty() || negative.is_empty() {
        return f64::NAN;
    }
    let mut all: Vec<(f64, bool)> = positive
        .iter()
        .map(|&v| (v, true))
        .chain(negative.iter().map(|&v| (v, false)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut rank_sum = 0.0;
    let mut i = 0;
    while i < all.len() {
        let mut j = i;
        while j + 1 < all.len() && all[j + 1].0 == all[i].0 {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        rank_sum += all[i..=j].iter().filter(|a| a.1).count() as f64 * rank;
        i = j + 1;
    }
    let n = positive.len() as f64;
    (rank_sum - n * (n + 1.0) / 2.0) / (n * negative.len() as f64)
}
