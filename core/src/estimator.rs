//! Estimator. Placeholder until written.
