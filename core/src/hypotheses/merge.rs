//! Near-duplicate hypotheses merged, the best kept.

use super::config::Spread;
use crate::config::MAX_CANDIDATES;

/// The largest difference between two states over the first `n`, in `spread` units (the
/// quaternion compared up to sign, since `q` and `−q` are one rotation).
pub fn distance(a: &[f32], b: &[f32], spread: &Spread) -> f32 {
    let n = a.len().min(b.len());
    let quaternion_sign =
        if n >= 4 && a[..4].iter().zip(&b[..4]).map(|(x, y)| x * y).sum::<f32>() < 0.0 {
            -1.0
        } else {
            1.0
        };
    let mut largest = 0.0f32;
    for i in 0..n {
        let other = if i < 4 { quaternion_sign * b[i] } else { b[i] };
        let d = libm::fabsf(a[i] - other) / spread.for_state(i).max(f32::MIN_POSITIVE);
        largest = largest.max(d);
    }
    largest
}

/// Picks from `scores` (one per candidate) the best first, skipping any candidate within
/// `merge_distance` of one already picked, up to `keep`; writes the picked indices to `out`
/// and returns how many. `state(i)` gives candidate `i`'s state. Ties keep the earlier index.
pub fn pick<'s>(
    scores: &[f32],
    state: impl Fn(usize) -> &'s [f32],
    spread: &Spread,
    merge_distance: f32,
    keep: usize,
    out: &mut [usize],
) -> usize {
    let keep = keep.min(out.len());
    let mut picked = 0;
    let mut taken = [false; MAX_CANDIDATES];
    let total = scores.len().min(taken.len());
    while picked < keep {
        let mut best: Option<usize> = None;
        for i in 0..total {
            if taken[i] {
                continue;
            }
            if best.is_none_or(|b| scores[i] > scores[b]) {
                best = Some(i);
            }
        }
        let Some(b) = best else { break };
        taken[b] = true;
        let near = out[..picked]
            .iter()
            .any(|&p| distance(state(p), state(b), spread) < merge_distance);
        if !near {
            out[picked] = b;
            picked += 1;
        }
    }
    picked
}

#[cfg(test)]
mod tests {
    use super::*;

    fn states() -> [[f32; 8]; 4] {
        let base = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 400.0, 0.2];
        let mut near = base;
        near[7] += 0.05; // 0.14 joint units away
        let mut far = base;
        far[7] += 0.7; // 2 joint units away
        let mut flipped = base;
        for v in &mut flipped[..4] {
            *v = -*v; // the same rotation
        }
        [base, near, far, flipped]
    }

    #[test]
    fn a_quaternion_and_its_negative_are_the_same_hypothesis() {
        let s = states();
        assert_eq!(distance(&s[0], &s[3], &Spread::default()), 0.0);
        assert!((distance(&s[0], &s[2], &Spread::default()) - 2.0).abs() < 1e-5);
    }

    #[test]
    fn near_duplicates_merge_into_the_better_and_capacity_holds() {
        let s = states();
        let scores = [0.8, 0.9, 0.7, 0.5];
        let mut out = [usize::MAX; 4];
        let n = pick(&scores, |i| &s[i][..], &Spread::default(), 0.3, 4, &mut out);
        // 1 beats its near twin 0 and the flipped copy 3; 2 is far enough to stay.
        assert_eq!(&out[..n], &[1, 2]);
        let n = pick(&scores, |i| &s[i][..], &Spread::default(), 0.3, 1, &mut out);
        assert_eq!(&out[..n], &[1]);
        let n = pick(&scores, |i| &s[i][..], &Spread::default(), 0.0, 3, &mut out);
        assert_eq!(&out[..n], &[1, 0, 2]);
    }
}
