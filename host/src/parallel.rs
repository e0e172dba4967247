//! Independent pieces of work spread over a few threads (the sweep's seeds, a variant's
//! runs): each item is taken once from a shared queue, and the results come back in the
//! items' order, whatever order the threads finished in.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `f` applied to every item of `items` on `jobs` threads (at least one, at most one per
/// item), the results in the order of `items`.
pub fn map<T: Sync, R: Send>(items: &[T], jobs: usize, f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let mut done: Vec<(usize, R)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..jobs.clamp(1, items.len().max(1)))
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        out.push((i, f(item)));
                    }
                    out
                })
            })
            .collect();
        workers
            .into_iter()
            // A worker's panic goes on in the caller, as if `f` had run there: no result is
            // dropped unseen.
            .flat_map(|w| {
                w.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    });
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_once_in_order() {
        let items: Vec<u64> = (0..101).collect();
        for jobs in [0, 1, 2, 7, 200, usize::MAX] {
            let squares = map(&items, jobs, |&x| x * x);
            assert_eq!(squares, items.iter().map(|x| x * x).collect::<Vec<_>>());
        }
        assert!(map(&[] as &[u8], 2, |&x| x).is_empty());
    }

    #[test]
    fn a_panic_in_one_item_reaches_the_caller() {
        let items: Vec<u32> = (0..10).collect();
        let caught = std::panic::catch_unwind(|| {
            map(&items, 2, |&x| {
                assert_ne!(x, 7, "item seven");
                x
            })
        });
        assert!(caught.is_err());
    }
}
