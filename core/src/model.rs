//! The kinematic hand model: the `hand.dh` format parsed into a fixed-capacity tree.
//!
//! Format (see `models/hand.dh` and `docs/hand-model.md`): one row per link frame,
//!
//! ```text
//! frame  name  theta  d  a  alpha  shape  next
//! ```
//!
//! with `T_i^next = Rot_z(theta) · Trans_z(d) · Trans_x(a) · Rot_x(alpha)`. `theta` is `base`
//! (frame 0 only: the palm's quaternion q0..q3 and translation q4..q6), a state `qN` (a
//! revolute joint; states numbered in table order) or a constant. Numbers may be written as
//! `1.5`, `pi`, `-pi/2`, `2*pi/3`. `shape` is `-`, `cyl R`, `tip R` or `box X Y Z [at CX CY CZ]`
//! (a box defaults to the palm convention: centred at (2.5, −9, 0) mm in its frame). `next` is
//! `-` or the list of child frames. `#` starts a comment.
//!
//! One optional extension (this project's, ignored by nothing else because it is a separate
//! row kind): `limit qN LO HI` gives a joint range in radians that the estimator enforces.

use core::fmt;

use heapless::{String, Vec};

use crate::config::{MAX_CHAIN, MAX_CHILDREN, MAX_LINKS, MAX_NAME_LEN, MAX_STATES};

/// The whole-hand model of the thesis (Table 2.1 / Appendix A) with the corrections of
/// `docs/hand-model.md` and the joint ranges of the project's test sequences.
pub const HAND_DH: &str = include_str!("../../models/hand.dh");

/// States taken by the palm's spatial transform: quaternion `(w, x, y, z)` then translation.
pub const BASE_STATES: usize = 7;

/// Centre of a `box` shape in its frame when the row gives none (mm): the palm convention.
pub const DEFAULT_BOX_CENTRE: [f32; 3] = [2.5, -9.0, 0.0];

/// How a frame's DH `theta` is set.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Theta {
    /// The palm's spatial transform (states q0..q6); the row's own transform is the identity.
    Base,
    /// A constant angle (rad).
    Const(f32),
    /// A revolute joint driven by state `qN` (rad).
    State(u8),
}

/// Geometry attached to a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Shape {
    /// No geometry.
    None,
    /// A rigid box: edge lengths and centre in the frame (mm).
    Box {
        /// Edge lengths along x, y, z (mm).
        size: [f32; 3],
        /// Centre in the frame (mm).
        centre: [f32; 3],
    },
    /// A capsule of this radius (mm) whose axis runs from this frame's origin to its child's.
    Cylinder {
        /// Radius (mm).
        radius: f32,
    },
    /// A fingertip: a point feature at this frame's origin; radius (mm).
    Tip {
        /// Fingertip radius (mm).
        radius: f32,
    },
}

/// One link frame of the kinematic tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Name from the table (`-` for none).
    pub name: String<MAX_NAME_LEN>,
    /// DH rotation about z.
    pub theta: Theta,
    /// DH offset along z (mm).
    pub d: f32,
    /// DH length along x (mm).
    pub a: f32,
    /// DH twist about x (rad).
    pub alpha: f32,
    /// Geometry on this frame.
    pub shape: Shape,
    /// The frame this one hangs from (`None` for the root).
    pub parent: Option<u8>,
    /// Frames listed in `next`.
    pub children: Vec<u8, MAX_CHILDREN>,
    /// 1-based line of the row in the source text.
    pub line: u32,
    /// `sin(alpha)` and `cos(alpha)`, computed once when the row is read.
    alpha_sin_cos: (f32, f32),
}

impl Link {
    /// `sin(alpha)` and `cos(alpha)` (libm's `sincosf`, computed when the model was read).
    pub fn alpha_sin_cos(&self) -> (f32, f32) {
        self.alpha_sin_cos
    }
}

/// A joint range (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limit {
    /// Smallest angle (rad).
    pub lo: f32,
    /// Largest angle (rad).
    pub hi: f32,
}

/// A parsed kinematic model: a tree of at most [`MAX_LINKS`] frames and [`MAX_STATES`] states.
///
/// Invariants (checked by [`Model::parse`]): frames are numbered 0.. in order; frame 0 is the
/// `base`; every other frame has exactly one parent; the tree has no cycle; joint states are
/// numbered q7, q8, ... in table order; `order` lists every frame after its parent.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    links: Vec<Link, MAX_LINKS>,
    order: Vec<u8, MAX_LINKS>,
    state_frame: [u8; MAX_STATES],
    limits: [Option<Limit>; MAX_STATES],
    n_states: u8,
}

/// What is wrong with a model text, and on which line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelError {
    /// 1-based line number of the offending row.
    pub line: u32,
    /// What is wrong.
    pub kind: ModelErrorKind,
}

/// The kinds of [`ModelError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ModelErrorKind {
    /// A row ended before this field.
    MissingField(&'static str),
    /// This field holds a word the format does not know.
    UnknownToken(&'static str),
    /// This field is not a finite number.
    BadNumber(&'static str),
    /// This length (mm) is a number but not above zero.
    NotPositive(&'static str),
    /// Tokens left after `next`.
    TrailingTokens,
    /// Frames must be numbered 0, 1, 2, ... in order.
    FrameOutOfOrder {
        /// The number this row should have had.
        expected: u16,
    },
    /// Joint states must be q7, q8, ... in table order, each used once.
    StateOutOfOrder {
        /// The state this row should have used.
        expected: u16,
    },
    /// `base` is allowed on frame 0 only, and frame 0 must be `base`.
    BaseNotFirst,
    /// `next` names a frame the table does not have.
    MissingFrame {
        /// The frame named.
        frame: u16,
    },
    /// A frame is named in `next` by two frames.
    TwoParents {
        /// The frame named twice.
        frame: u16,
    },
    /// Following `next` leads back to where it started.
    Cycle {
        /// A frame on the cycle.
        frame: u16,
    },
    /// A frame no `next` reaches from the palm.
    Unreachable {
        /// The frame.
        frame: u16,
    },
    /// More than [`MAX_LINKS`] frames.
    TooManyFrames,
    /// `next` names a frame number at or past [`MAX_LINKS`]: no model can have it.
    FrameBeyondLimit {
        /// The frame named.
        frame: u16,
    },
    /// More than [`MAX_STATES`] states.
    TooManyStates,
    /// More than [`MAX_CHILDREN`] frames in one `next`.
    TooManyChildren,
    /// A chain deeper than [`MAX_CHAIN`] revolute joints.
    ChainTooDeep,
    /// A name longer than [`MAX_NAME_LEN`].
    NameTooLong,
    /// A `limit` row naming a state that is not a joint, or with `lo > hi`.
    BadLimit,
    /// The text holds no frame (reported on its last line, or line 0 for an empty text).
    Empty,
}

impl fmt::Display for ModelErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingField(field) => write!(f, "missing field `{field}`"),
            Self::UnknownToken(field) => write!(f, "unknown token in field `{field}`"),
            Self::BadNumber(field) => write!(f, "field `{field}` is not a finite number"),
            Self::NotPositive(field) => {
                write!(f, "field `{field}` must be a length above 0 (mm)")
            }
            Self::TrailingTokens => write!(f, "unexpected tokens after `next`"),
            Self::FrameOutOfOrder { expected } => {
                write!(f, "frames out of order: expected frame {expected}")
            }
            Self::StateOutOfOrder { expected } => {
                write!(f, "states out of order: expected q{expected}")
            }
            Self::BaseNotFirst => write!(f, "frame 0, and only frame 0, must have theta `base`"),
            Self::MissingFrame { frame } => write!(f, "`next` names missing frame {frame}"),
            Self::TwoParents { frame } => {
                write!(f, "frame {frame} is named in `next` of two frames")
            }
            Self::Cycle { frame } => write!(f, "cycle in `next` through frame {frame}"),
            Self::Unreachable { frame } => write!(f, "frame {frame} is not reached from frame 0"),
            Self::TooManyFrames => {
                write!(
                    f,
                    "more than {MAX_LINKS} frames (a model has at most {MAX_LINKS})"
                )
            }
            Self::FrameBeyondLimit { frame } => write!(
                f,
                "`next` names frame {frame}, but a model has at most {MAX_LINKS} frames \
                 (0 to {})",
                MAX_LINKS - 1
            ),
            Self::TooManyStates => write!(f, "more than {MAX_STATES} states"),
            Self::TooManyChildren => write!(f, "more than {MAX_CHILDREN} frames in `next`"),
            Self::ChainTooDeep => write!(f, "more than {MAX_CHAIN} joints in one chain"),
            Self::NameTooLong => write!(f, "name longer than {MAX_NAME_LEN} characters"),
            Self::BadLimit => write!(f, "`limit qN LO HI` needs a joint state and LO <= HI"),
            Self::Empty => write!(f, "no frames"),
        }
    }
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.kind)
    }
}

impl core::error::Error for ModelError {}

impl Model {
    /// The built-in whole-hand model ([`HAND_DH`]).
    pub fn hand() -> Result<Self, ModelError> {
        Self::parse(HAND_DH)
    }

    /// Parses the `hand.dh` format. Never panics; every defect is a [`ModelError`].
    pub fn parse(text: &str) -> Result<Self, ModelError> {
        let mut links: Vec<Link, MAX_LINKS> = Vec::new();
        let mut limits = [None; MAX_STATES];
        let mut state_frame = [0u8; MAX_STATES];
        let mut n_states: usize = 0;
        for (index, raw) in text.lines().enumerate() {
            let line = index as u32 + 1;
            let content = raw.split('#').next().unwrap_or("");
            let mut tokens = content.split_whitespace().peekable();
            let Some(&first) = tokens.peek() else {
                continue;
            };
            let err = |kind| ModelError { line, kind };
            if first == "limit" {
                tokens.next();
                let (state, limit) = parse_limit(&mut tokens).map_err(err)?;
                match limits.get_mut(state) {
                    Some(slot) if state >= BASE_STATES && state < n_states => *slot = Some(limit),
                    _ => return Err(err(ModelErrorKind::BadLimit)),
                }
                continue;
            }
            let frame_number = links.len();
            let mut row = parse_row(&mut tokens, frame_number as u16, line).map_err(err)?;
            match row.link.theta {
                Theta::Base if frame_number == 0 => n_states = BASE_STATES,
                Theta::Base => return Err(err(ModelErrorKind::BaseNotFirst)),
                _ if frame_number == 0 => return Err(err(ModelErrorKind::BaseNotFirst)),
                Theta::State(s) => {
                    if usize::from(s) != n_states {
                        return Err(err(ModelErrorKind::StateOutOfOrder {
                            expected: n_states as u16,
                        }));
                    }
                    let slot = state_frame
                        .get_mut(n_states)
                        .ok_or(err(ModelErrorKind::TooManyStates))?;
                    *slot = frame_number as u8;
                    n_states += 1;
                }
                Theta::Const(_) => {}
            }
            row.link.children = row.children;
            links
                .push(row.link)
                .map_err(|_| err(ModelErrorKind::TooManyFrames))?;
        }
        if links.is_empty() {
            return Err(ModelError {
                line: text.lines().count() as u32,
                kind: ModelErrorKind::Empty,
            });
        }
        let order = link_tree(&mut links)?;
        let model = Model {
            links,
            order,
            state_frame,
            limits,
            n_states: n_states as u8,
        };
        for (i, link) in model.links.iter().enumerate() {
            if model.chain(i).is_none() {
                return Err(ModelError {
                    line: link.line,
                    kind: ModelErrorKind::ChainTooDeep,
                });
            }
        }
        Ok(model)
    }

    /// The link frames, in table order.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// Frame indices in an order where every frame follows its parent.
    pub fn order(&self) -> &[u8] {
        &self.order
    }

    /// Number of states (28 for the whole hand).
    pub fn n_states(&self) -> usize {
        usize::from(self.n_states)
    }

    /// The frame whose theta is joint state `state`, if `state` is a joint state.
    pub fn joint_frame(&self, state: usize) -> Option<usize> {
        (BASE_STATES..self.n_states())
            .contains(&state)
            .then(|| usize::from(self.state_frame[state]))
    }

    /// The range of joint state `state`, when the model gives one.
    pub fn limit(&self, state: usize) -> Option<Limit> {
        self.limits.get(state).copied().flatten()
    }

    /// Sets (or clears) the range of joint state `state`; false if it is not a joint state.
    /// Also false, changing nothing, for a range that is not finite or has `lo > hi`.
    pub fn set_limit(&mut self, state: usize, limit: Option<Limit>) -> bool {
        let valid = limit.is_none_or(|l| l.lo.is_finite() && l.hi.is_finite() && l.lo <= l.hi);
        if self.joint_frame(state).is_none() || !valid {
            return false;
        }
        self.limits[state] = limit;
        true
    }

    /// The frame with this name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name.as_str() == name)
    }

    /// The joint states that move frame `frame`'s shape, root first: every revolute joint on
    /// the path from the palm to `frame`, including `frame`'s own (its shape turns with it).
    /// `None` only if the chain is deeper than [`MAX_CHAIN`] (rejected by [`Model::parse`]).
    pub fn chain(&self, frame: usize) -> Option<Vec<u8, MAX_CHAIN>> {
        let mut chain: Vec<u8, MAX_CHAIN> = Vec::new();
        let mut cursor = Some(frame);
        let mut steps = 0;
        while let Some(f) = cursor {
            let link = self.links.get(f)?;
            if let Theta::State(s) = link.theta {
                chain.push(s).ok()?;
            }
            cursor = link.parent.map(usize::from);
            steps += 1;
            if steps > MAX_LINKS {
                return None;
            }
        }
        chain.reverse();
        Some(chain)
    }
}

struct Row {
    link: Link,
    children: Vec<u8, MAX_CHILDREN>,
}

fn parse_row<'a>(
    tokens: &mut impl Iterator<Item = &'a str>,
    expected_frame: u16,
    line: u32,
) -> Result<Row, ModelErrorKind> {
    let mut field = |name: &'static str| tokens.next().ok_or(ModelErrorKind::MissingField(name));
    let frame: u16 = field("frame")?
        .parse()
        .map_err(|_| ModelErrorKind::BadNumber("frame"))?;
    if frame != expected_frame {
        return Err(ModelErrorKind::FrameOutOfOrder {
            expected: expected_frame,
        });
    }
    let name_token = field("name")?;
    let mut name = String::new();
    name.push_str(name_token)
        .map_err(|_| ModelErrorKind::NameTooLong)?;
    let theta_token = field("theta")?;
    let theta = if theta_token == "base" {
        Theta::Base
    } else if let Some(n) = theta_token.strip_prefix('q') {
        let n: u16 = n
            .parse()
            .map_err(|_| ModelErrorKind::UnknownToken("theta"))?;
        if usize::from(n) >= MAX_STATES {
            return Err(ModelErrorKind::TooManyStates);
        }
        Theta::State(n as u8)
    } else {
        Theta::Const(parse_number(theta_token, "theta")?)
    };
    let d = parse_number(field("d")?, "d")?;
    let a = parse_number(field("a")?, "a")?;
    let alpha = parse_number(field("alpha")?, "alpha")?;
    let shape = match field("shape")? {
        "-" => Shape::None,
        "cyl" => Shape::Cylinder {
            radius: parse_length(field("radius")?, "radius")?,
        },
        "tip" => Shape::Tip {
            radius: parse_length(field("radius")?, "radius")?,
        },
        "box" => {
            let size = [
                parse_length(field("box x")?, "box x")?,
                parse_length(field("box y")?, "box y")?,
                parse_length(field("box z")?, "box z")?,
            ];
            Shape::Box {
                size,
                centre: DEFAULT_BOX_CENTRE,
            }
        }
        _ => return Err(ModelErrorKind::UnknownToken("shape")),
    };
    let mut shape = shape;
    let mut children: Vec<u8, MAX_CHILDREN> = Vec::new();
    let mut saw_next = false;
    let mut dash_next = false;
    while let Some(tok) = tokens.next() {
        if tok == "at" && !saw_next {
            if let Shape::Box { centre, .. } = &mut shape {
                for c in centre.iter_mut() {
                    let t = tokens
                        .next()
                        .ok_or(ModelErrorKind::MissingField("box centre"))?;
                    *c = parse_number(t, "box centre")?;
                }
                continue;
            }
            return Err(ModelErrorKind::UnknownToken("shape"));
        }
        if dash_next {
            return Err(ModelErrorKind::TrailingTokens);
        }
        if tok == "-" && !saw_next {
            dash_next = true;
            saw_next = true;
            continue;
        }
        saw_next = true;
        let child: u16 = tok
            .parse()
            .map_err(|_| ModelErrorKind::UnknownToken("next"))?;
        if usize::from(child) >= MAX_LINKS {
            return Err(ModelErrorKind::FrameBeyondLimit { frame: child });
        }
        children
            .push(child as u8)
            .map_err(|_| ModelErrorKind::TooManyChildren)?;
    }
    if !saw_next {
        return Err(ModelErrorKind::MissingField("next"));
    }
    Ok(Row {
        link: Link {
            name,
            theta,
            d,
            a,
            alpha,
            shape,
            parent: None,
            children: Vec::new(),
            line,
            alpha_sin_cos: crate::float::sin_cos(alpha),
        },
        children,
    })
}

fn parse_limit<'a>(
    tokens: &mut impl Iterator<Item = &'a str>,
) -> Result<(usize, Limit), ModelErrorKind> {
    let state = tokens
        .next()
        .ok_or(ModelErrorKind::MissingField("limit state"))?
        .strip_prefix('q')
        .ok_or(ModelErrorKind::UnknownToken("limit state"))?
        .parse::<usize>()
        .map_err(|_| ModelErrorKind::UnknownToken("limit state"))?;
    let lo = parse_number(
        tokens.next().ok_or(ModelErrorKind::MissingField("lo"))?,
        "lo",
    )?;
    let hi = parse_number(
        tokens.next().ok_or(ModelErrorKind::MissingField("hi"))?,
        "hi",
    )?;
    if tokens.next().is_some() {
        return Err(ModelErrorKind::TrailingTokens);
    }
    if lo > hi {
        return Err(ModelErrorKind::BadLimit);
    }
    Ok((state, Limit { lo, hi }))
}

/// Parses `[-]A[*B][/C]` where each factor is a decimal or `pi`.
fn parse_number(token: &str, field: &'static str) -> Result<f32, ModelErrorKind> {
    let (negative, body) = match token.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, token.strip_prefix('+').unwrap_or(token)),
    };
    let mut parts = body.splitn(2, '/');
    let numerator = parts.next().unwrap_or("");
    let mut value = 1.0f32;
    for factor in numerator.split('*') {
        value *= parse_factor(factor, field)?;
    }
    if let Some(denominator) = parts.next() {
        let d = parse_factor(denominator, field)?;
        if d == 0.0 {
            return Err(ModelErrorKind::BadNumber(field));
        }
        value /= d;
    }
    let value = if negative { -value } else { value };
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ModelErrorKind::BadNumber(field))
    }
}

fn parse_factor(token: &str, field: &'static str) -> Result<f32, ModelErrorKind> {
    if token == "pi" {
        return Ok(core::f32::consts::PI);
    }
    let starts_numeric = token
        .bytes()
        .next()
        .is_some_and(|b| b.is_ascii_digit() || b == b'.');
    if !starts_numeric {
        return Err(ModelErrorKind::UnknownToken(field));
    }
    match token.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(ModelErrorKind::BadNumber(field)),
    }
}

fn parse_length(token: &str, field: &'static str) -> Result<f32, ModelErrorKind> {
    let v = parse_number(token, field)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(ModelErrorKind::NotPositive(field))
    }
}

/// Sets parents from the `next` lists, checks the tree, and returns a parent-first order.
fn link_tree(links: &mut Vec<Link, MAX_LINKS>) -> Result<Vec<u8, MAX_LINKS>, ModelError> {
    let n = links.len();
    for i in 0..n {
        let line = links[i].line;
        let children = links[i].children.clone();
        for &c in &children {
            let c = usize::from(c);
            let err = |kind| ModelError { line, kind };
            if c >= n {
                return Err(err(ModelErrorKind::MissingFrame { frame: c as u16 }));
            }
            if c == 0 || c == i {
                return Err(err(ModelErrorKind::Cycle { frame: c as u16 }));
            }
            if links[c].parent.is_some() {
                return Err(err(ModelErrorKind::TwoParents { frame: c as u16 }));
            }
            links[c].parent = Some(i as u8);
        }
    }
    let mut order: Vec<u8, MAX_LINKS> = Vec::new();
    let _ = order.push(0);
    let mut head = 0;
    while head < order.len() {
        let f = usize::from(order[head]);
        head += 1;
        for &c in &links[f].children {
            if order.push(c).is_err() {
                return Err(ModelError {
                    line: links[f].line,
                    kind: ModelErrorKind::Cycle {
                        frame: u16::from(c),
                    },
                });
            }
        }
    }
    for (i, link) in links.iter().enumerate() {
        if !order.contains(&(i as u8)) {
            let kind = if link.parent.is_some() {
                ModelErrorKind::Cycle { frame: i as u16 }
            } else {
                ModelErrorKind::Unreachable { frame: i as u16 }
            };
            return Err(ModelError {
                line: link.line,
                kind,
            });
        }
    }
    Ok(order)
}
