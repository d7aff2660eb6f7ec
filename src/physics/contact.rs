//! Contact between a body's convex pieces and another body's planar faces (thesis 2.5, 6.5):
//! IMPACT normal force (eq. 2.1-2.3) at the centroid of the overlap volume, ADAMS Coulomb
//! friction (eq. 4.5) opposite the slip velocity, and the contact area as overlap volume /
//! penetration depth. Each touching (piece, face) pair is one track.

use super::body::BodyFrame;
use super::forces::{apply, Wrench};
use super::friction::FrictionParams;
use super::impact::ImpactParams;
use crate::geometry::{shape_halfspace_overlap, ConvexShape, HalfSpace, PlaneOverlap};
use nalgebra::{Isometry3, Point3, Unit, Vector3};

/// A contact definition between two bodies (one ADAMS CONTACT statement).
#[derive(Debug, Clone)]
pub struct Contact {
    /// Name for reports ("cube-tube", "mid_shoe-rail").
    pub name: String,
    /// Body carrying the convex pieces.
    pub body_a: usize,
    /// Convex pieces of body a with their pose in a's frame.
    pub pieces_a: Vec<(Isometry3<f64>, ConvexShape)>,
    /// Body carrying the planar faces.
    pub body_b: usize,
    /// Faces of body b as half-spaces in b's frame (normal out of the material).
    pub faces_b: Vec<HalfSpace>,
    /// Normal force law.
    pub impact: ImpactParams,
    /// Friction law (None: frictionless).
    pub friction: Option<FrictionParams>,
}

/// State of one active track at one instant.
#[derive(Debug, Clone, Copy)]
pub struct TrackState {
    /// Index of the contact in the system.
    pub contact: u32,
    /// Track index within the contact: piece * faces + face.
    pub track: u32,
    /// Penetration of the deepest point, m.
    pub penetration: f64,
    /// Penetration rate, m/s (positive approaching).
    pub penetration_rate: f64,
    /// Contact area = overlap volume / penetration, m².
    pub area: f64,
    /// Normal force magnitude, N.
    pub normal_force: f64,
    /// Tangential slip velocity of a relative to b at the contact point, m/s, world.
    pub slip_velocity: Vector3<f64>,
    /// Contact point (overlap centroid), world.
    pub point: Point3<f64>,
    /// Contact normal (out of b, pushing a), world.
    pub normal: Vector3<f64>,
    /// Friction force magnitude, N.
    pub friction_force: f64,
}

impl TrackState {
    /// Mean contact pressure N/A, Pa (0 without area).
    pub fn pressure(&self) -> f64 {
        if self.area > 0.0 {
            self.normal_force / self.area
        } else {
            0.0
        }
    }
}

/// What [`Contact::evaluate`] does with the overlap geometry of each (piece, face) pair.
///
/// The finite-difference Jacobian perturbs velocities in half of its columns; those columns
/// leave every pose unchanged, so the overlap geometry (85 % of a right-hand side) is computed
/// once and replayed, giving bit-identical forces at a fraction of the cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GeometryMode {
    /// Compute every overlap (normal evaluation).
    #[default]
    Compute,
    /// Compute every overlap and remember it in evaluation order.
    Record,
    /// Reuse the overlaps remembered by the last `Record` pass (same poses only).
    Replay,
}

/// Overlaps remembered between a `Record` pass and `Replay` passes over the same poses.
#[derive(Debug, Clone, Default)]
pub struct GeometryCache {
    /// Current mode.
    pub mode: GeometryMode,
    entries: Vec<Option<PlaneOverlap>>,
    cursor: usize,
}

impl GeometryCache {
    /// Switches mode; `Record` forgets the old entries, `Replay` rewinds to the first one.
    pub fn set_mode(&mut self, mode: GeometryMode) {
        self.mode = mode;
        self.cursor = 0;
        if mode == GeometryMode::Record {
            self.entries.clear();
        }
    }

    #[inline]
    fn overlap(
        &mut self,
        shape: &ConvexShape,
        pose: &Isometry3<f64>,
        hs: &HalfSpace,
    ) -> Option<PlaneOverlap> {
        match self.mode {
            GeometryMode::Compute => shape_halfspace_overlap(shape, pose, hs),
            GeometryMode::Record => {
                let ov = shape_halfspace_overlap(shape, pose, hs);
                self.entries.push(ov);
                ov
            }
            GeometryMode::Replay => {
                let ov = match self.entries.get(self.cursor) {
                    Some(ov) => *ov,
                    // Fewer entries than pairs: the record pass was for another system.
                    None => shape_halfspace_overlap(shape, pose, hs),
                };
                self.cursor += 1;
                ov
            }
        }
    }
}

impl Contact {
    /// Evaluates all tracks; adds forces to `wrenches` when given, and calls `sink` per active
    /// track. Returns the elastic potential energy stored (∫ k w^e dw), J.
    pub fn evaluate(
        &self,
        index: u32,
        frames: &[BodyFrame],
        wrenches: Option<&mut [Wrench]>,
        sink: &mut dyn FnMut(&TrackState),
    ) -> f64 {
        self.evaluate_with(index, frames, wrenches, sink, &mut GeometryCache::default())
    }

    /// [`Contact::evaluate`] with the overlap geometry computed, recorded or replayed as
    /// `geometry.mode` says.
    pub fn evaluate_with(
        &self,
        index: u32,
        frames: &[BodyFrame],
        mut wrenches: Option<&mut [Wrench]>,
        sink: &mut dyn FnMut(&TrackState),
        geometry: &mut GeometryCache,
    ) -> f64 {
        let fa = &frames[self.body_a];
        let fb = &frames[self.body_b];
        let iso_a = fa.isometry();
        let mut energy = 0.0;
        let nfaces = self.faces_b.len();
        for (ip, (piece_pose, shape)) in self.pieces_a.iter().enumerate() {
            let pose = iso_a * piece_pose;
            for (jf, face) in self.faces_b.iter().enumerate() {
                let n_world = fb.rotation * face.normal.into_inner();
                let offset_world = face.offset + n_world.dot(&fb.position);
                let hs = HalfSpace {
                    normal: Unit::new_unchecked(n_world),
                    offset: offset_world,
                };
                let Some(ov) = geometry.overlap(shape, &pose, &hs) else {
                    continue;
                };
                let w = ov.depth;
                // Penetration rate from the material point at the deepest point (envelope).
                let v_rel_deep =
                    fa.point_velocity(&ov.deepest_point) - fb.point_velocity(&ov.deepest_point);
                let wdot = -v_rel_deep.dot(&n_world);
                let fn_mag = self.impact.force(w, wdot);
                let c = ov.centroid;
                let v_rel = fa.point_velocity(&c) - fb.point_velocity(&c);
                let slip = v_rel - n_world * v_rel.dot(&n_world);
                let speed = slip.norm();
                let mut ft = 0.0;
                let mut force = n_world * fn_mag;
                if let Some(fr) = &self.friction {
                    if speed > 0.0 && fn_mag > 0.0 {
                        ft = fr.coefficient(speed) * fn_mag;
                        force -= slip * (ft / speed);
                    }
                }
                if let Some(wr) = wrenches.as_deref_mut() {
                    apply(wr, frames, self.body_a, &c, force);
                    apply(wr, frames, self.body_b, &c, -force);
                }
                let e = self.impact.exponent;
                energy += self.impact.stiffness * w.powf(e + 1.0) / (e + 1.0);
                sink(&TrackState {
                    contact: index,
                    track: (ip * nfaces + jf) as u32,
                    penetration: w,
                    penetration_rate: wdot,
                    area: ov.area,
                    normal_force: fn_mag,
                    slip_velocity: slip,
                    point: c,
                    normal: n_world,
                    friction_force: ft,
                });
            }
        }
        energy
    }
}
