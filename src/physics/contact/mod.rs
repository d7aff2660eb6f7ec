//! Contact between a body's convex pieces and another body's planar faces (thesis 2.5, 6.5;
//! SPEC §2 "Passivity"; docs/reference/models.md "Contact formulation").
//!
//! Each piece carries fixed contact points on its surface ([`crate::geometry::lattice`]): small
//! balls whose stiffness and damping shares `β` sum to 1 over any face of the piece. Every
//! point that penetrates a face's solid ([`PlacedFace`], bounded or not) by `w` gets its own
//! IMPACT force (eq. 2.1-2.3) `β max(0, k w^e + c STEP(w) ẇ)` along the solid's outward normal
//! and ADAMS Coulomb friction (eq. 4.5) opposite its own slip, both applied at the point's
//! ball surface, with `w`, `ẇ` and the slip of that same material point. Hence:
//! - the elastic force is the exact gradient of the stored energy
//!   `U = Σ β k w^(e+1)/(e+1)`, continuous in the configuration (each `w` is a continuous
//!   function of the poses: a ball's depth into a convex solid);
//! - damping does the work `−β c STEP ẇ² <= 0` (or `−β k w^e ẇ <= 0` while the clamp holds),
//!   friction `−μ N |v_slip| <= 0`: the contact is passive by construction;
//! - a face pressed uniformly by `w` gives `Σ β k w^e = k w^e`, the thesis' law for the face.
//!
//! With [`FaceContact::Exact`] a rounded box's faces are instead integrated over their pressed
//! polygons (the lattice's limit; `face.rs`, docs/reference/models.md "Exact face contact"): its
//! quadrature nodes are points of the same law (`point.rs`).
//!
//! Each touching (piece, face) pair is one track: its normal force is the points' sum, its
//! contact point their centre of pressure, its slip the force-weighted mean slip (and the
//! force-weighted mean slip speed, so `N · slip_speed` is the friction work rate over μ), its
//! area the thesis 2.5 area (overlap volume of the piece with the face's plane / depth) scaled
//! to the face's extent, its penetration the deepest point's.

use super::body::BodyFrame;
use super::forces::Wrench;
use super::friction::FrictionParams;
use super::impact::ImpactParams;
use crate::geometry::{
    contact_points, ContactPoint, ConvexShape, FaceExtent, HalfSpace, PlacedFace,
    DEFAULT_POINTS_PER_EDGE,
};
use nalgebra::{Isometry3, Matrix3, Point3, Unit, Vector3};

mod face;
mod geometry_cache;
mod moments;
mod point;
mod reduced;

pub use face::{FaceContact, FrictionRule};
pub use geometry_cache::{GeometryCache, GeometryMode, PATCH_REUSE};
pub(crate) use moments::Matrix6x12;
pub use moments::TrackMoments;
use point::{PointOutputs, TrackSum};
pub use reduced::{ReducedCensus, ReducedShare, REDUCED_TOLERANCE};

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
    /// In-plane extent of each face in b's frame (`None`: unbounded); empty: all unbounded.
    pub face_extents: Vec<Option<FaceExtent>>,
    /// Normal force law (the whole face's: each contact point carries its share).
    pub impact: ImpactParams,
    /// Friction law (None: frictionless).
    pub friction: Option<FrictionParams>,
    /// How the rounded boxes' faces are resolved (contact points or exact integration).
    pub face_contact: FaceContact,
    /// Where the exact face contact evaluates friction: at every node (the per-point law,
    /// always in a case) or per part (a measurement, `railwear-bench face-states`).
    pub friction_rule: FrictionRule,
    /// The largest a-priori estimate of friction per part's relative error a part of the
    /// reduced face law ([`FaceContact::Reduced`]) may have and take it (default
    /// [`REDUCED_TOLERANCE`]); parts above it take the per-node law.
    pub reduced_tolerance: f64,
    /// How the reduced face law took its parts (shared by the contact's clones).
    pub reduced_census: std::sync::Arc<ReducedCensus>,
    /// Contact points of each piece, in the piece's frame.
    points: Vec<Vec<ContactPoint>>,
}

impl Contact {
    /// A contact with unbounded faces and [`DEFAULT_POINTS_PER_EDGE`] contact points per box
    /// edge.
    pub fn new(
        name: impl Into<String>,
        body_a: usize,
        pieces_a: Vec<(Isometry3<f64>, ConvexShape)>,
        body_b: usize,
        faces_b: Vec<HalfSpace>,
        impact: ImpactParams,
        friction: Option<FrictionParams>,
    ) -> Self {
        let mut c = Self {
            name: name.into(),
            body_a,
            pieces_a,
            body_b,
            faces_b,
            face_extents: Vec::new(),
            impact,
            friction,
            face_contact: FaceContact::default(),
            friction_rule: FrictionRule::default(),
            reduced_tolerance: REDUCED_TOLERANCE,
            reduced_census: Default::default(),
            points: Vec::new(),
        };
        c.set_points_per_edge(DEFAULT_POINTS_PER_EDGE);
        c
    }

    /// Bounds the faces: one entry per face of `faces_b`, `None` leaving a face unbounded.
    pub fn with_face_extents(mut self, extents: Vec<Option<FaceExtent>>) -> Self {
        self.face_extents = extents;
        self
    }

    /// Contact points per box edge (see [`crate::geometry::lattice`]).
    pub fn with_points_per_edge(mut self, n: usize) -> Self {
        self.set_points_per_edge(n);
        self
    }

    /// How the rounded boxes' faces are resolved (see [`FaceContact`]).
    pub fn with_face_contact(mut self, face_contact: FaceContact) -> Self {
        self.face_contact = face_contact;
        self
    }

    /// The reduced face law's tolerance ([`Contact::reduced_tolerance`]).
    pub fn with_reduced_tolerance(mut self, tolerance: f64) -> Self {
        self.reduced_tolerance = tolerance;
        self
    }

    /// Where the exact face contact evaluates friction ([`FrictionRule`]).
    pub fn with_friction_rule(mut self, rule: FrictionRule) -> Self {
        self.friction_rule = rule;
        self
    }

    fn set_points_per_edge(&mut self, n: usize) {
        self.points = self
            .pieces_a
            .iter()
            .map(|(_, shape)| contact_points(shape, n))
            .collect();
    }

    /// Contact points of piece `i`, in its frame.
    pub fn points(&self, piece: usize) -> &[ContactPoint] {
        &self.points[piece]
    }
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
    /// Force-weighted mean tangential slip velocity of a relative to b, m/s, world.
    pub slip_velocity: Vector3<f64>,
    /// Force-weighted mean slip speed `Σ N_i |v_i| / N`, m/s (`N · slip_speed` is the
    /// friction work rate divided by μ; the wear law's `N v_slip`, eq. 3.13).
    pub slip_speed: f64,
    /// Centre of pressure of the track's point forces (the deepest point when N = 0), world.
    pub point: Point3<f64>,
    /// Contact normal (out of b, pushing a), world.
    pub normal: Vector3<f64>,
    /// Sum of the points' friction force magnitudes, N.
    pub friction_force: f64,
    /// Power dissipated by the IMPACT damping (and the force clamp), W (>= 0).
    pub damping_power: f64,
    /// Power dissipated by friction `Σ μ_i N_i |v_i|`, W (>= 0).
    pub friction_power: f64,
    /// The track's total contact force on body a (normal and friction, the points' sum), N,
    /// world (−force acts on b): its part off `normal` is the friction force.
    pub force: Vector3<f64>,
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

/// One touching contact point's load at one instant, for what wear needs below the track's
/// sums (the distribution of point pressures, each point's slip): handed out by
/// [`Contact::evaluate_points`] before the [`TrackState`] of the point's track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Index of the contact in the system.
    pub contact: u32,
    /// Track index within the contact (as [`TrackState::track`]).
    pub track: u32,
    /// The point's normal force `β max(0, k w^e + c STEP ẇ)`, N.
    pub normal_force: f64,
    /// The point's share `β` of the face's stiffness and damping (sums to 1 over a face).
    pub weight: f64,
    /// The point's own slip speed, m/s.
    pub slip_speed: f64,
}

/// Which nodes' force derivatives a linearizing evaluation takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JacobianScope {
    /// Every point's and node's: the exact contact Jacobian.
    #[default]
    Exact,
    /// A Newton matrix: the exact face contact leaves out the nodes of a piece's side faces
    /// (turned more than 72.5° from the plane) while they are pressed in slivers, and takes a
    /// facing face's strips beyond a bounded face's side on 9 nodes instead of 50 (per-node
    /// friction). Every force is still evaluated at every node; only derivatives are left out.
    /// What that costs Newton is its contraction, measured and bounded in docs/reference/models.md "The
    /// Newton matrix leaves out the side faces".
    NewtonMatrix,
}

/// What an evaluation hands out besides forces and tracks (each when given): every active
/// track's force derivatives, and every touching point's load.
#[derive(Default)]
pub struct EvaluationOutputs<'a> {
    /// Receives each active track's force derivatives per contact point or node, when
    /// `moments` is not given.
    pub linearizations: Option<&'a mut Vec<TrackLinearization>>,
    /// Receives the force derivatives one sum per track instead (the points' or nodes'
    /// derivatives as moments; taken only together with `linearizations`).
    pub moments: Option<&'a mut Vec<TrackMoments>>,
    /// Receives each touching contact point's load.
    pub points: Option<&'a mut dyn FnMut(&PointLoad)>,
    /// Which nodes' derivatives are taken (when they are).
    pub scope: JacobianScope,
}

/// Local derivatives of one contact point's force at one instant, for the contact-aware Newton
/// matrix ([`MultibodySystem::contact_jacobian`](super::system::MultibodySystem::contact_jacobian)).
///
/// The force on body a is `F = n f_n(w, ẇ) + F_t(s, f_n)` at the point `p` (−F on b), with `w`
/// the penetration of the point's ball, `ẇ` its rate and `s` the slip velocity at `p`: force,
/// point and rates belong to the same material point, so the derivatives through `w`, `ẇ` and
/// `s` are exact, and [`MultibodySystem::contact_jacobian`](super::system::MultibodySystem::contact_jacobian) adds the terms through the point's
/// motion. Held fixed: the turn of the normal at a face's edge or with body b.
#[derive(Debug, Clone, Copy)]
pub struct TrackLinearization {
    /// Body carrying the pieces (force +F).
    pub body_a: usize,
    /// Body carrying the faces (force −F).
    pub body_b: usize,
    /// Deepest point of the ball (where F acts and `w` is measured), world.
    pub deepest_point: Point3<f64>,
    /// Where F acts (the same point), world.
    pub point: Point3<f64>,
    /// Centre of the point's ball (the material point of body a), world.
    pub centre: Point3<f64>,
    /// The force on body a, N, world.
    pub force: Vector3<f64>,
    /// Contact normal (out of b), world.
    pub normal: Vector3<f64>,
    /// ∂f_n/∂w, N/m.
    pub dfn_dw: f64,
    /// ∂f_n/∂ẇ, N·s/m.
    pub dfn_dwdot: f64,
    /// ∂F/∂f_n: `n − μ ŝ` (dimensionless, world).
    pub dforce_dfn: Vector3<f64>,
    /// ∂F/∂s, N·s/m (world; zero without friction).
    pub dforce_dslip: Matrix3<f64>,
}

impl TrackLinearization {
    /// `∂F/∂v_rel` at the point: `∂F/∂s P − (∂f_n/∂ẇ) (∂F/∂f_n) nᵀ`, taking `∂F/∂s P = ∂F/∂s`
    /// (the slip derivative maps and yields tangential vectors only, see
    /// `friction_derivatives`), given `∂F/∂f_n` and the normal.
    #[inline]
    pub fn dforce_slip_with_rate(
        &self,
        dforce_dfn: &Vector3<f64>,
        normal: &Vector3<f64>,
    ) -> Matrix3<f64> {
        self.dforce_dslip - dforce_dfn * (normal.transpose() * self.dfn_dwdot)
    }
}

/// Absolute part of the margin of the contact points' plane cull, m: far above the rounding
/// difference (~1e-16 of the coordinates) between the plane distance in the piece's frame and
/// in the world.
const CULL_MARGIN_M: f64 = 1e-12;
/// Relative part of the cull margin (of the plane offset and the piece's distance from the
/// world origin, the magnitudes the two frames' roundings scale with).
const CULL_MARGIN_REL: f64 = 1e-13;

/// The contact points' plane cull: a face's plane in a piece's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlaneCull {
    normal: Vector3<f64>,
    offset: f64,
    margin: f64,
}

impl PlaneCull {
    /// The plane of `hs` (world) seen from a piece placed by `pose`.
    #[inline]
    pub(crate) fn new(pose: &Isometry3<f64>, hs: &HalfSpace) -> Self {
        let n_world = hs.normal.into_inner();
        Self {
            normal: pose.rotation.inverse_transform_vector(&n_world),
            offset: hs.offset - n_world.dot(&pose.translation.vector),
            margin: CULL_MARGIN_M
                + CULL_MARGIN_REL * (hs.offset.abs() + pose.translation.vector.norm()),
        }
    }

    /// True when the point's ball centre lies farther above the plane than its radius (plus
    /// the rounding margin): then its penetration into the face's solid is negative.
    #[inline]
    pub(crate) fn misses(&self, point: &ContactPoint) -> bool {
        self.normal.dot(&point.local.coords) - self.offset > point.radius + self.margin
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
        self.evaluate_with(
            index,
            frames,
            wrenches,
            sink,
            &mut GeometryCache::default(),
            EvaluationOutputs::default(),
        )
    }

    /// [`Contact::evaluate`] that also hands every touching point's load to `points` (each
    /// track's points before its [`TrackState`] reaches `sink`).
    pub fn evaluate_points(
        &self,
        index: u32,
        frames: &[BodyFrame],
        sink: &mut dyn FnMut(&TrackState),
        points: &mut dyn FnMut(&PointLoad),
    ) -> f64 {
        self.evaluate_with(
            index,
            frames,
            None,
            sink,
            &mut GeometryCache::default(),
            EvaluationOutputs {
                points: Some(points),
                ..Default::default()
            },
        )
    }

    /// [`Contact::evaluate`] with the overlap geometry computed, recorded or replayed as
    /// `geometry.mode` says; pushes each active track's force derivatives to `linearizations`
    /// when given, and each touching point's load to `points` when given.
    pub fn evaluate_with(
        &self,
        index: u32,
        frames: &[BodyFrame],
        mut wrenches: Option<&mut [Wrench]>,
        sink: &mut dyn FnMut(&TrackState),
        geometry: &mut GeometryCache,
        outputs: EvaluationOutputs<'_>,
    ) -> f64 {
        let EvaluationOutputs {
            mut linearizations,
            mut moments,
            mut points,
            scope,
        } = outputs;
        let fa = &frames[self.body_a];
        let fb = &frames[self.body_b];
        let iso_a = fa.isometry();
        let iso_b = fb.isometry();
        let mut energy = 0.0;
        let nfaces = self.faces_b.len();
        let replay_from = self.begin_pairs(index, geometry);
        // The per-part friction's node records ([`FrictionRule::PerPart`], linearized only):
        // one buffer for the whole evaluation, cleared per part.
        let mut lump_nodes = Vec::new();
        for (ip, (piece_pose, shape)) in self.pieces_a.iter().enumerate() {
            let pose = iso_a * piece_pose;
            for (jf, face) in self.faces_b.iter().enumerate() {
                let hs = face_in_world(face, fb);
                // The piece's overlap with the face's plane: the gate (no point of a piece
                // clear of the plane can touch the face's solid) and the thesis 2.5 area.
                let pair = replay_from.map(|start| start + ip * nfaces + jf);
                let ov = geometry.overlap(pair, shape, &pose, &hs);
                let Some(ov) = ov else {
                    continue;
                };
                let placed = self.placed_face(jf, hs, &iso_b);
                // The nodes (exact face contact) or points (lattice) sum their derivatives into
                // one block per track when the moments are taken.
                let mut track_moments = (linearizations.is_some() && moments.is_some())
                    .then(|| TrackMoments::new(self.body_a, self.body_b, fa, fb));
                let mut out = PointOutputs {
                    index,
                    track: (ip * nfaces + jf) as u32,
                    linearizations: linearizations.as_deref_mut(),
                    moments: track_moments.as_mut(),
                    points: points.as_deref_mut(),
                    energy: &mut energy,
                    sum: TrackSum::default(),
                    tangent: PointOutputs::NO_TANGENT,
                    lump: None,
                    lump_nodes: &mut lump_nodes,
                    scope,
                };
                match (self.face_contact, shape) {
                    (
                        FaceContact::Exact | FaceContact::Reduced,
                        ConvexShape::RoundedBox {
                            half_extents,
                            roundover,
                        },
                    ) => {
                        let inner = half_extents.map(|h| (h - roundover).max(0.0));
                        self.evaluate_faces(
                            fa, fb, &pose, &inner, *roundover, ov.depth, &placed, &mut out,
                        );
                    }
                    _ => {
                        // Narrow-phase cull: a point whose ball centre lies farther above the
                        // face's plane than its radius cannot touch the face's solid (the
                        // distance to the solid is at least the distance to its plane). The
                        // test runs in the piece's frame (three multiply-adds instead of
                        // placing the point in the world); `cull_margin` covers the rounding
                        // between the two frames, so only points whose world evaluation gives
                        // `w <= 0` are skipped: no result changes.
                        let cull = PlaneCull::new(&pose, &hs);
                        for point in &self.points[ip] {
                            if cull.misses(point) {
                                continue;
                            }
                            let centre = pose * point.local;
                            let (distance, normal) = placed.signed_distance(&centre);
                            self.evaluate_point(
                                fa,
                                fb,
                                &centre,
                                point.radius,
                                point.weight,
                                distance,
                                &normal,
                                &mut out,
                            );
                        }
                    }
                }
                let track = out.sum;
                if let (Some(sum), Some(all)) = (track_moments, moments.as_deref_mut()) {
                    if !sum.is_empty() {
                        all.push(sum);
                    }
                }
                if !track.touching {
                    continue;
                }
                if let Some(wr) = wrenches.as_deref_mut() {
                    wr[self.body_a].0 += track.force;
                    wr[self.body_a].1 += track.torque_a;
                    wr[self.body_b].0 -= track.force;
                    wr[self.body_b].1 -= track.torque_b;
                }
                let n_total = track.normal_force;
                let (slip_velocity, slip_speed, point) = if n_total > 0.0 {
                    (
                        track.weighted_slip / n_total,
                        track.weighted_speed / n_total,
                        Point3::from(track.weighted_point / n_total),
                    )
                } else {
                    (Vector3::zeros(), 0.0, track.deepest_point)
                };
                sink(&TrackState {
                    contact: index,
                    track: (ip * nfaces + jf) as u32,
                    penetration: track.penetration,
                    penetration_rate: track.penetration_rate,
                    area: ov.area * placed.coverage(shape, &pose),
                    normal_force: n_total,
                    slip_velocity,
                    slip_speed,
                    point,
                    normal: track.normal,
                    friction_force: track.friction_force,
                    damping_power: track.damping_power,
                    friction_power: track.friction_power,
                    force: track.force,
                });
            }
        }
        energy
    }
}

impl Contact {
    /// Where this contact's (piece, face) pairs read their overlaps from in `geometry`
    /// ([`GeometryCache::begin`]): `Some(first entry)` to replay, freeze or refresh.
    fn begin_pairs(&self, index: u32, geometry: &mut GeometryCache) -> Option<usize> {
        geometry.begin(
            index as usize,
            self.pieces_a.len() * self.faces_b.len(),
            self.body_a,
            self.body_b,
        )
    }

    /// Face `jf` of body b (placed as `iso_b`, its world half-space `hs`) with its extent.
    fn placed_face(&self, jf: usize, hs: HalfSpace, iso_b: &Isometry3<f64>) -> PlacedFace {
        PlacedFace::new(
            hs,
            self.face_extents.get(jf).and_then(Option::as_ref),
            iso_b,
        )
    }

    /// At an implicit step's accepted state, whose tracks came from its last Newton iterate:
    /// each (piece, face) pair's overlap as `geometry.mode` says (the caller sets
    /// [`GeometryMode::Refresh`]: the patches the next step's iterates hold), and each of this
    /// contact's `tracks` given the thesis 2.5 area at these poses. A track whose pair is clear
    /// of its plane here (it separated within Newton's last update) keeps its area.
    pub fn refresh_areas(
        &self,
        index: u32,
        frames: &[BodyFrame],
        geometry: &mut GeometryCache,
        tracks: &mut [TrackState],
    ) {
        let fa = &frames[self.body_a];
        let fb = &frames[self.body_b];
        let (iso_a, iso_b) = (fa.isometry(), fb.isometry());
        let nfaces = self.faces_b.len();
        let replay_from = self.begin_pairs(index, geometry);
        for (ip, (piece_pose, shape)) in self.pieces_a.iter().enumerate() {
            let pose = iso_a * piece_pose;
            for (jf, face) in self.faces_b.iter().enumerate() {
                let hs = face_in_world(face, fb);
                let pair = replay_from.map(|start| start + ip * nfaces + jf);
                let Some(ov) = geometry.overlap(pair, shape, &pose, &hs) else {
                    continue;
                };
                let id = (ip * nfaces + jf) as u32;
                if let Some(track) = tracks
                    .iter_mut()
                    .find(|t| t.contact == index && t.track == id)
                {
                    let placed = self.placed_face(jf, hs, &iso_b);
                    track.area = ov.area * placed.coverage(shape, &pose);
                }
            }
        }
    }
}

/// A face of body b placed by its frame: the world half-space.
#[inline]
fn face_in_world(face: &HalfSpace, fb: &BodyFrame) -> HalfSpace {
    let n_world = fb.rotation * face.normal.into_inner();
    HalfSpace {
        normal: Unit::new_unchecked(n_world),
        offset: face.offset + n_world.dot(&fb.position),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_plane_cull_skips_only_points_that_cannot_touch() {
        // A rounded box (a launcher shoe head's size) far from the origin, in random poses
        // around a bounded face (a lip top ending at a slot edge) and an unbounded one: every
        // culled point has a negative penetration by the exact world evaluation, and the cull
        // removes the points clear of the plane.
        let shape = ConvexShape::RoundedBox {
            half_extents: Vector3::new(0.019, 0.005, 0.04),
            roundover: 5e-4,
        };
        let points = contact_points(&shape, DEFAULT_POINTS_PER_EDGE);
        let hs = HalfSpace {
            normal: Unit::new_normalize(Vector3::new(0.0, 1.0, 0.0)),
            offset: -0.03,
        };
        let extent = FaceExtent {
            origin: Point3::new(0.0, -0.03, 0.6),
            tangent: Vector3::z_axis(),
            s_range_m: (-0.85, 0.85),
            t_range_m: (f64::NEG_INFINITY, 0.005),
        };
        let base = Isometry3::translation(0.2, 0.4, 0.6);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut culled, mut touching) = (0usize, 0usize);
        for trial in 0..2000 {
            let rot: UnitQuaternion<f64> = UnitQuaternion::from_euler_angles(
                rng.gen_range(-0.05..0.05),
                rng.gen_range(-3.2..3.2),
                rng.gen_range(-0.05..0.05),
            );
            // Centre so that the lowest point sits within ±1 mm of the plane.
            let half_height: f64 = (0..3)
                .map(|k| {
                    let axis: Vector3<f64> = rot.inverse_transform_vector(&Vector3::y());
                    (shape_half(&shape, k) - 5e-4) * axis[k].abs()
                })
                .sum::<f64>()
                + 5e-4;
            let y = -0.03 + half_height + rng.gen_range(-1e-3..1e-3);
            let pose = Isometry3::from_parts(
                Translation3::new(rng.gen_range(-0.03..0.03), y, rng.gen_range(-0.5..0.5)),
                rot,
            );
            let frame = base; // the face's body, placed away from the origin
            let pose = frame * pose;
            let hs_world = HalfSpace {
                normal: Unit::new_normalize(frame.rotation * hs.normal.into_inner()),
                offset: hs.offset
                    + (frame.rotation * hs.normal.into_inner()).dot(&frame.translation.vector),
            };
            let ext = (trial % 2 == 0).then_some(&extent);
            let placed = PlacedFace::new(hs_world, ext, &frame);
            let cull = PlaneCull::new(&pose, &hs_world);
            for p in &points {
                let (d, _) = placed.signed_distance(&(pose * p.local));
                let w = p.radius - d;
                if cull.misses(p) {
                    culled += 1;
                    assert!(w <= 0.0, "culled point penetrates by {w:e} m");
                } else if w > 0.0 {
                    touching += 1;
                }
            }
        }
        assert!(touching > 1000, "the poses must press points into the face");
        assert!(
            culled > 2000 * points.len() / 2,
            "most points are clear of the plane: {culled} culled"
        );
    }

    fn shape_half(shape: &ConvexShape, k: usize) -> f64 {
        match shape {
            ConvexShape::RoundedBox { half_extents, .. } => half_extents[k],
            ConvexShape::Sphere { radius } => *radius,
        }
    }
}
