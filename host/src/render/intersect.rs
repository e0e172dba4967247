//! Ray intersections with the renderer's primitives, in camera coordinates (mm).
//!
//! Rays start at the camera centre (the origin) and run along a unit direction `d`; a hit is
//! the distance `t` (mm) along the ray and the outward unit surface normal there.

use nalgebra::Vector3;

/// A ray hit: distance along the ray (mm) and outward unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance from the camera centre along the unit ray direction (mm).
    pub t: f64,
    /// Outward unit surface normal (camera coordinates).
    pub normal: Vector3<f64>,
}

/// A capsule: the segment `a`–`b` swept by a sphere of radius `r` (mm, camera coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// One end of the axis (mm).
    pub a: Vector3<f64>,
    /// The other end of the axis (mm).
    pub b: Vector3<f64>,
    /// Radius (mm).
    pub r: f64,
}

/// An oriented box (mm, camera coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    /// Centre (mm).
    pub centre: Vector3<f64>,
    /// The box's unit axes.
    pub axes: [Vector3<f64>; 3],
    /// Half the edge length along each axis (mm).
    pub half: [f64; 3],
}

/// The nearest intersection of the ray `t · d` (t > 0, `d` unit) with a capsule.
pub fn ray_capsule(d: &Vector3<f64>, c: &Capsule) -> Option<Hit> {
    let ba = c.b - c.a;
    let oa = -c.a;
    let baba = ba.dot(&ba);
    let bard = ba.dot(d);
    let baoa = ba.dot(&oa);
    let rdoa = d.dot(&oa);
    let oaoa = oa.dot(&oa);
    let r2 = c.r * c.r;
    // The infinite cylinder, kept only where the hit lies between the end caps.
    let qa = baba - bard * bard;
    if qa > 1e-12 * baba.max(1.0) {
        let qb = baba * rdoa - baoa * bard;
        let qc = baba * oaoa - baoa * baoa - r2 * baba;
        let h = qb * qb - qa * qc;
        if h < 0.0 {
            return None;
        }
        let t = (-qb - h.sqrt()) / qa;
        let y = baoa + t * bard;
        if t > 0.0 && y > 0.0 && y < baba {
            let p = d * t;
            let axis_point = c.a + ba * (y / baba);
            return Some(Hit {
                t,
                normal: (p - axis_point) / c.r,
            });
        }
    }
    // Otherwise the nearer of the two end spheres.
    let sa = ray_sphere(d, &c.a, c.r);
    let sb = ray_sphere(d, &c.b, c.r);
    match (sa, sb) {
        (Some(x), Some(y)) => Some(if x.t <= y.t { x } else { y }),
        (x, y) => x.or(y),
    }
}

/// The nearest intersection of the ray `t · d` (t > 0, `d` unit) with a sphere.
pub fn ray_sphere(d: &Vector3<f64>, centre: &Vector3<f64>, r: f64) -> Option<Hit> {
    let b = d.dot(centre);
    let c = centre.dot(centre) - r * r;
    let h = b * b - c;
    if h < 0.0 {
        return None;
    }
    let t = b - h.sqrt();
    if t <= 0.0 {
        return None;
    }
    Some(Hit {
        t,
        normal: (d * t - centre) / r,
    })
}

/// The nearest intersection of the ray `t · d` (t > 0, `d` unit) with an oriented box.
pub fn ray_box(d: &Vector3<f64>, bx: &OrientedBox) -> Option<Hit> {
    let mut t_near = f64::NEG_INFINITY;
    let mut t_far = f64::INFINITY;
    let mut near_axis = 0;
    let mut near_sign = 1.0;
    for (k, axis) in bx.axes.iter().enumerate() {
        // The ray in the box's coordinates: origin o = -centre, direction dd.
        let o = -axis.dot(&bx.centre);
        let dd = axis.dot(d);
        if dd.abs() < 1e-15 {
            if o.abs() > bx.half[k] {
                return None;
            }
            continue;
        }
        let t1 = (-bx.half[k] - o) / dd;
        let t2 = (bx.half[k] - o) / dd;
        let (lo, hi, sign) = if t1 < t2 {
            (t1, t2, -1.0)
        } else {
            (t2, t1, 1.0)
        };
        if lo > t_near {
            t_near = lo;
            near_axis = k;
            near_sign = sign;
        }
        t_far = t_far.min(hi);
        if t_near > t_far {
            return None;
        }
    }
    if t_near <= 0.0 || !t_near.is_finite() {
        return None;
    }
    Some(Hit {
        t: t_near,
        normal: bx.axes[near_axis] * near_sign,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    #[test]
    fn capsule_side_and_caps() {
        let c = Capsule {
            a: v(-10.0, 0.0, 100.0),
            b: v(10.0, 0.0, 100.0),
            r: 5.0,
        };
        let hit = ray_capsule(&v(0.0, 0.0, 1.0), &c).unwrap();
        assert!((hit.t - 95.0).abs() < 1e-9);
        assert!((hit.normal - v(0.0, 0.0, -1.0)).norm() < 1e-9);
        // Through the cap beyond b: the sphere at b.
        let d = v(12.0, 0.0, 100.0).normalize();
        let hit = ray_capsule(&d, &c).unwrap();
        assert!(((d * hit.t - c.b).norm() - 5.0).abs() < 1e-9);
        // Past the cap: a miss.
        assert!(ray_capsule(&v(15.5, 0.0, 100.0).normalize(), &c).is_none());
        // A capsule along the ray: the near sphere.
        let along = Capsule {
            a: v(0.0, 0.0, 150.0),
            b: v(0.0, 0.0, 100.0),
            r: 5.0,
        };
        assert!((ray_capsule(&v(0.0, 0.0, 1.0), &along).unwrap().t - 95.0).abs() < 1e-9);
    }

    #[test]
    fn box_faces() {
        let bx = OrientedBox {
            centre: v(0.0, 0.0, 100.0),
            axes: [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)],
            half: [10.0, 20.0, 5.0],
        };
        let hit = ray_box(&v(0.0, 0.0, 1.0), &bx).unwrap();
        assert!((hit.t - 95.0).abs() < 1e-9);
        assert_eq!(hit.normal, v(0.0, 0.0, -1.0));
        assert!(ray_box(&v(11.0, 0.0, 95.0).normalize(), &bx).is_none());
        assert!(ray_box(&v(9.0, 0.0, 95.0).normalize(), &bx).is_some());
    }
}
