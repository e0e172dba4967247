//! Tracker. Placeholder until written.
