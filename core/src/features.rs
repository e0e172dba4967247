//! Slice features (Sec. 4.3.1). Placeholder until written.
