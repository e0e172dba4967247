//! Where a score reads a frame's edge map, so a map built for that score
//! ([`EdgeMap::build_edges_for`](super::EdgeMap::build_edges_for)) need only cover those cells.
//!
//! A score reads the map at the silhouette points of each link (the chamfer term, truncated at
//! [`LikelihoodConfig::chamfer_cap_px`]) and the edge marks of the cells within the hand's
//! image bounds widened by [`LikelihoodConfig::reverse_margin_px`] (the reverse term). Every
//! point read lies within the hand's bounds ([`crate::silhouette::hand_bounds`]: each link's
//! bounds hold its silhouette points). A truncated chamfer distance depends only on the edges
//! within the cap of the point read, along a path inside the box they span; a mark only on its
//! own cell's pixels. So a map whose cells are exact within the bounds grown by
//! [`reach_cells`] reads the same, bit for bit, as one built over the whole frame.

use crate::projection::Bounds;

use super::LikelihoodConfig;

/// A rectangle of map cells: columns `x0..x1`, rows `y0..y1` (half-open; empty when either
/// range is).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CellRect {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl CellRect {
    /// Every cell of a `cols × rows` grid.
    pub fn all(cols: usize, rows: usize) -> Self {
        CellRect {
            x0: 0,
            y0: 0,
            x1: cols,
            y1: rows,
        }
    }

    /// No cell.
    pub const EMPTY: CellRect = CellRect {
        x0: 0,
        y0: 0,
        x1: 0,
        y1: 0,
    };

    /// Whether it holds no cell.
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// Whether every cell of `other` is one of these.
    pub fn contains(&self, other: &CellRect) -> bool {
        other.is_empty()
            || (self.x0 <= other.x0
                && self.y0 <= other.y0
                && other.x1 <= self.x1
                && other.y1 <= self.y1)
    }

    /// Cells of the rectangle.
    pub fn cells(&self) -> usize {
        if self.is_empty() {
            0
        } else {
            (self.x1 - self.x0) * (self.y1 - self.y0)
        }
    }
}

/// Where a score reads one camera's map.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Reads {
    /// Nowhere: nothing of the hand is projected into the camera (the default, to add to).
    #[default]
    Nowhere,
    /// Within these image bounds (px, finite).
    Within(Bounds),
    /// Anywhere in the frame: bounds not known, or not finite.
    Everywhere,
}

impl Reads {
    /// These reads and those within `bounds` (a hand's, or `None` when nothing of it is
    /// projected): bounds that are not finite read everywhere.
    pub fn with(self, bounds: Option<Bounds>) -> Reads {
        let Some(b) = bounds else {
            return self;
        };
        let finite = b.min.x.is_finite()
            && b.min.y.is_finite()
            && b.max.x.is_finite()
            && b.max.y.is_finite();
        if !finite {
            return Reads::Everywhere;
        }
        match self {
            Reads::Nowhere => Reads::Within(b),
            Reads::Within(a) => Reads::Within(Bounds {
                min: a.min.inf(&b.min),
                max: a.max.sup(&b.max),
            }),
            Reads::Everywhere => Reads::Everywhere,
        }
    }

    /// The cells of a `cols × rows` grid of `stride_px` cells that must be exact for these
    /// reads under `config`.
    pub fn cells(
        &self,
        cols: usize,
        rows: usize,
        stride_px: usize,
        config: &LikelihoodConfig,
    ) -> CellRect {
        let bounds = match self {
            Reads::Nowhere => return CellRect::EMPTY,
            Reads::Everywhere => return CellRect::all(cols, rows),
            Reads::Within(b) => b,
        };
        let Some(reach) = reach_cells(config, stride_px) else {
            return CellRect::all(cols, rows);
        };
        let s = stride_px.max(1) as f32;
        // A cell index of a coordinate (px), as `EdgeMap` and the reverse term take it: the
        // floor of `v / s` for `v ≥ 0`, 0 below; at most `n`.
        let cell = |v: f32, n: usize| -> usize {
            if v > 0.0 {
                ((v / s) as usize).min(n)
            } else {
                0
            }
        };
        let (cx0, cx1) = (cell(bounds.min.x, cols), cell(bounds.max.x, cols));
        let (cy0, cy1) = (cell(bounds.min.y, rows), cell(bounds.max.y, rows));
        CellRect {
            x0: cx0.saturating_sub(reach),
            y0: cy0.saturating_sub(reach),
            x1: cx1.saturating_add(reach + 1).min(cols),
            y1: cy1.saturating_add(reach + 1).min(rows),
        }
    }
}

/// Cells around a read's own cell whose edges can change what it returns under `config`: the
/// chamfer cap, and the reverse term's margin with the cell it rounds up to, in cells, plus one
/// for rounding. `None` when either is not finite (read everywhere).
pub fn reach_cells(config: &LikelihoodConfig, stride_px: usize) -> Option<usize> {
    let s = stride_px.max(1) as f32;
    let reach_px = config
        .chamfer_cap_px
        .max(0.0)
        .max(config.reverse_margin_px.max(0.0) + s);
    if !reach_px.is_finite() || reach_px > 1e6 {
        return None;
    }
    Some(libm::ceilf(reach_px / s) as usize + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nalgebra::Vector2;

    fn bounds(x0: f32, y0: f32, x1: f32, y1: f32) -> Bounds {
        Bounds {
            min: Vector2::new(x0, y0),
            max: Vector2::new(x1, y1),
        }
    }

    #[test]
    fn reads_join_bounds_and_fall_back_to_everywhere() {
        let r = Reads::Nowhere.with(None);
        assert_eq!(r, Reads::Nowhere);
        let r = r.with(Some(bounds(10.0, 20.0, 30.0, 40.0)));
        assert_eq!(r, Reads::Within(bounds(10.0, 20.0, 30.0, 40.0)));
        let r = r.with(Some(bounds(5.0, 25.0, 35.0, 30.0)));
        assert_eq!(r, Reads::Within(bounds(5.0, 20.0, 35.0, 40.0)));
        assert_eq!(r.with(None), r);
        assert_eq!(
            r.with(Some(bounds(f32::NAN, 0.0, 1.0, 1.0))),
            Reads::Everywhere
        );
        assert_eq!(
            Reads::Everywhere.with(Some(bounds(0.0, 0.0, 1.0, 1.0))),
            Reads::Everywhere
        );
    }

    #[test]
    fn the_cells_read_grow_by_the_reach_and_stay_on_the_grid() {
        let config = LikelihoodConfig::default();
        // Cap 24 px, reverse margin 8 px + a 4 px cell: 6 cells, and one for rounding.
        assert_eq!(reach_cells(&config, 4), Some(7));
        let r = Reads::Within(bounds(100.0, 60.0, 200.0, 90.0));
        assert_eq!(
            r.cells(160, 120, 4, &config),
            CellRect {
                x0: 25 - 7,
                y0: 15 - 7,
                x1: 50 + 8,
                y1: 22 + 8
            }
        );
        // At the frame's edges, and beyond them, the rectangle stays on the grid.
        let r = Reads::Within(bounds(-50.0, -5.0, 700.0, 10.0));
        assert_eq!(
            r.cells(160, 120, 4, &config),
            CellRect {
                x0: 0,
                y0: 0,
                x1: 160,
                y1: 2 + 8
            }
        );
        assert_eq!(Reads::Nowhere.cells(160, 120, 4, &config), CellRect::EMPTY);
        assert_eq!(
            Reads::Everywhere.cells(160, 120, 4, &config),
            CellRect::all(160, 120)
        );
        let endless = LikelihoodConfig {
            chamfer_cap_px: f32::INFINITY,
            ..config
        };
        assert_eq!(r.cells(160, 120, 4, &endless), CellRect::all(160, 120));
    }

    #[test]
    fn a_rectangle_contains_its_parts_and_any_empty_one() {
        let big = CellRect::all(10, 8);
        let part = CellRect {
            x0: 2,
            y0: 3,
            x1: 5,
            y1: 8,
        };
        assert!(big.contains(&part));
        assert!(!part.contains(&big));
        assert!(part.contains(&CellRect::EMPTY));
        assert_eq!(part.cells(), 15);
        assert_eq!(CellRect::EMPTY.cells(), 0);
    }
}
