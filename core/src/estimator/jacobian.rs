//! The link Jacobian: how one link's image axis and radii move with each state (Eq. 2.16
//! through the camera).

use heapless::Vec;
use nalgebra::Vector2;

use crate::camera::Camera;
use crate::config::MAX_ROW_NONZEROS;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::projection::ProjectedLink;

/// How the image measurements of one link move with each state it depends on.
#[derive(Debug, Clone, Default)]
pub struct LinkJacobian {
    /// The states, palm first then the link's joint chain.
    pub states: Vec<u8, MAX_ROW_NONZEROS>,
    /// `∂a/∂q` for the axis start in the image (px per unit state).
    pub da: Vec<Vector2<f32>, MAX_ROW_NONZEROS>,
    /// `∂b/∂q` for the axis end in the image.
    pub db: Vec<Vector2<f32>, MAX_ROW_NONZEROS>,
    /// `∂r0/∂q` for the projected radius at the start (px).
    pub dr0: Vec<f32, MAX_ROW_NONZEROS>,
    /// `∂r1/∂q` for the projected radius at the end (px).
    pub dr1: Vec<f32, MAX_ROW_NONZEROS>,
}

impl LinkJacobian {
    /// Computes the derivatives of link `link`'s image axis and radii (Eq. 2.16 through the
    /// camera). Left empty if an end does not project.
    #[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
    pub fn compute(&mut self, model: &Model, poses: &Poses, camera: &Camera, link: &ProjectedLink) {
        self.states.clear();
        self.da.clear();
        self.db.clear();
        self.dr0.clear();
        self.dr1.clear();
        let frame = usize::from(link.frame);
        let (Some((_, z0, j0)), Some((_, z1, j1))) = (
            camera.project_with_jacobian(&link.p0),
            camera.project_with_jacobian(&link.p1),
        ) else {
            return;
        };
        let depth_row = camera.r.row(2).into_owned();
        let d0 = poses.point_derivatives(model, frame, &link.p0);
        let d1 = poses.point_derivatives(model, frame, &link.p1);
        for ((s, v0), (_, v1)) in d0.iter().zip(d1.iter()) {
            let _ = self.states.push(*s);
            let _ = self.da.push(j0 * v0);
            let _ = self.db.push(j1 * v1);
            let _ = self
                .dr0
                .push(-link.radius_at(0.0) / z0 * (depth_row * v0)[0]);
            let _ = self
                .dr1
                .push(-link.radius_at(1.0) / z1 * (depth_row * v1)[0]);
        }
    }
}
