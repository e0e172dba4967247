//! The image likelihood of a whole state over every camera: the one scorer, in
//! [`crate::likelihood`], which the search and its acceptance use too.

pub use crate::likelihood::StateScorer;
