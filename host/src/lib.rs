//! The host side of digiteyes: sequence I/O, the synthetic renderer, tracking and evaluation
//! of recorded sequences. The `digiteyes` binary is a thin command-line layer over this crate.
