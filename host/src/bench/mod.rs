//! `digiteyes bench`: measurements that take more than a test should (`robustness`: the
//! tracker on a randomised sweep of rigs and motions).

pub mod robustness;
