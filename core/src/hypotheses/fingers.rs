//! The fingers of a model, found from its kinematic tree: the joint states that hang from
//! the same first joint below the palm form one finger (the whole hand has five).

use heapless::Vec;

use crate::config::MAX_STATES;
use crate::model::{Model, BASE_STATES};

/// Most fingers told apart.
pub const MAX_FINGERS: usize = 6;

/// Each joint state's finger: `of[s]` is the index of the finger of joint state `s` (in
/// order of first joint state), `None` for palm states.
#[derive(Debug, Clone, PartialEq)]
pub struct Fingers {
    of: [Option<u8>; MAX_STATES],
    count: usize,
}

impl Fingers {
    /// The fingers of `model`. Joint states past [`MAX_FINGERS`] fingers are left out.
    pub fn of(model: &Model) -> Self {
        let mut of = [None; MAX_STATES];
        let mut roots: Vec<u8, MAX_FINGERS> = Vec::new();
        let n = model.n_states().min(MAX_STATES);
        for (s, finger) in of.iter_mut().enumerate().take(n).skip(BASE_STATES) {
            let Some(root) = model
                .joint_frame(s)
                .and_then(|f| model.chain(f))
                .and_then(|c| c.first().copied())
            else {
                continue;
            };
            let index = match roots.iter().position(|&r| r == root) {
                Some(i) => i,
                None => {
                    if roots.push(root).is_err() {
                        continue;
                    }
                    roots.len() - 1
                }
            };
            *finger = Some(index as u8);
        }
        Fingers {
            of,
            count: roots.len(),
        }
    }

    /// How many fingers.
    pub fn count(&self) -> usize {
        self.count
    }

    /// True when joint state `s` belongs to finger `finger`.
    pub fn contains(&self, finger: usize, s: usize) -> bool {
        self.of.get(s).copied().flatten() == Some(finger as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hand_has_five_fingers_of_four_and_a_thumb_of_five() {
        let model = Model::hand().unwrap();
        let fingers = Fingers::of(&model);
        assert_eq!(fingers.count(), 5);
        let sizes: [usize; 5] =
            core::array::from_fn(|f| (0..MAX_STATES).filter(|&s| fingers.contains(f, s)).count());
        assert_eq!(sizes, [4, 4, 4, 4, 5]);
        assert!((0..BASE_STATES).all(|s| (0..5).all(|f| !fingers.contains(f, s))));
    }
}
