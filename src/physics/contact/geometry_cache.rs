//! The overlap geometry of a contact's (piece, face) pairs kept between evaluations: what
//! [`Contact::evaluate`](super::Contact::evaluate) computes, records, replays, refreshes or
//! holds frozen ([`GeometryMode`]), and the bound under which a refreshed overlap is reused
//! ([`PATCH_REUSE`]). Part of a run's checkpoint.

use crate::geometry::{
    shape_halfspace_depth, shape_halfspace_overlap, ConvexShape, HalfSpace, PlaneOverlap,
};
use nalgebra::{Isometry3, Point3, Vector3};

/// What [`Contact::evaluate`](super::Contact::evaluate) does with the overlap geometry of each (piece, face) pair.
///
/// The finite-difference Jacobian perturbs one state entry per column. Velocity columns leave
/// every pose unchanged, and a pose column of one body leaves the contacts of the other bodies
/// unchanged; those contacts replay the overlaps (85 % of a right-hand side) recorded at the
/// unperturbed state, which gives bit-identical forces at a fraction of the cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum GeometryMode {
    /// Compute every overlap (normal evaluation).
    #[default]
    Compute,
    /// Compute every overlap and remember it.
    Record,
    /// Reuse the overlaps remembered by the last `Record` pass: every pose is the recorded one.
    Replay,
    /// Poses of all bodies but this one are the recorded ones: contacts not touching it replay.
    ReplayExcept(usize),
    /// Like `Record`, but a pair whose plane moved, relative to its piece, by less than
    /// [`PATCH_REUSE`] of the recorded penetration since its overlap was last computed keeps
    /// that overlap (centroid held on the piece, area and volume as computed); its penetration,
    /// deepest point and normal force are computed exactly. The start of each implicit step.
    Refresh,
    /// Poses near the recorded ones (the Newton iterates of one implicit step): penetration,
    /// deepest point and hence the normal force are computed exactly from the support
    /// function; the overlap's centroid (held fixed on the piece) and area are those recorded.
    /// A pair that was apart when recorded and touches now is computed in full and remembered.
    Frozen,
}

/// `Refresh` keeps a pair's overlap while `|Δc| + R |Δn| <= PATCH_REUSE · w` (plane offset `c`
/// and unit normal `n` in the piece's frame, `R` the piece's bounding radius, `w` the recorded
/// penetration). Then every point of the piece has moved along the normal by at most
/// `δ = PATCH_REUSE · w` relative to the plane, so the overlap changed only within the slab
/// `|u| <= δ` about the cut. Brunn-Minkowski (the square root of a convex body's section area is
/// concave along the normal) bounds the cut area by `3 V / w` and the sections within the slab
/// by `(1 + δ/w)²` times it, so the volume is off by at most `6 PATCH_REUSE (1 + PATCH_REUSE)²`
/// of itself, the area `V / w` by about `7 PATCH_REUSE`, and the centroid by about
/// `12 PATCH_REUSE R`: with 1e-4, 0.07 % of the area (0.01 % of the wear rate through
/// `K(σ) ∝ σ^(1/6.3)`) and 0.12 % of the piece's size. Tested in `models::system_tests`.
pub const PATCH_REUSE: f64 = 1e-4;

/// Overlaps remembered between a `Record` pass and replays over the same poses. Part of a
/// run's checkpoint: `Refresh` keeps an overlap while its plane barely moved, so what the
/// next step sees depends on when each overlap was last computed.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct GeometryCache {
    /// Current mode.
    pub mode: GeometryMode,
    /// Overlap of every (piece, face) pair of every contact, in evaluation order.
    pub(super) entries: Vec<Option<PlaneOverlap>>,
    /// Centroid of each recorded overlap in its piece's frame (for `Frozen` and `Refresh`).
    local_centroids: Vec<Point3<f64>>,
    /// The plane (unit normal, offset) of each recorded overlap in its piece's frame.
    local_planes: Vec<(Vector3<f64>, f64)>,
    /// Index of each contact's first entry.
    contact_start: Vec<usize>,
}

impl GeometryCache {
    /// Switches mode; `Record` forgets the old entries.
    pub fn set_mode(&mut self, mode: GeometryMode) {
        self.mode = mode;
        if mode == GeometryMode::Record {
            self.entries.clear();
            self.local_centroids.clear();
            self.local_planes.clear();
            self.contact_start.clear();
        }
    }

    /// Where contact `index` (with `pairs` piece-face pairs between bodies `a` and `b`) reads
    /// its overlaps from: `Some(first entry)` to replay, `None` to compute. Registers the
    /// contact when recording.
    pub(super) fn begin(
        &mut self,
        index: usize,
        pairs: usize,
        a: usize,
        b: usize,
    ) -> Option<usize> {
        let replay = match self.mode {
            GeometryMode::Compute => false,
            GeometryMode::Record => {
                self.register(index);
                false
            }
            GeometryMode::Refresh => {
                let known = self
                    .contact_start
                    .get(index)
                    .and_then(|start| start.checked_add(pairs))
                    .is_some_and(|end| end <= self.entries.len());
                if !known {
                    self.register(index);
                }
                known
            }
            GeometryMode::Replay | GeometryMode::Frozen => true,
            GeometryMode::ReplayExcept(body) => body != a && body != b,
        };
        let start = *self.contact_start.get(index)?;
        (replay
            && start
                .checked_add(pairs)
                .is_some_and(|end| end <= self.entries.len()))
        .then_some(start)
    }

    /// The overlap of a piece placed by `pose` with the half-space `hs`, as the mode says: from
    /// entry `pair` (replayed, frozen or refreshed), or computed, and recorded when the mode
    /// records, when the contact reads no entries (`pair` is `None`, [`Self::begin`]).
    #[inline]
    pub(super) fn overlap(
        &mut self,
        pair: Option<usize>,
        shape: &ConvexShape,
        pose: &Isometry3<f64>,
        hs: &HalfSpace,
    ) -> Option<PlaneOverlap> {
        match (pair, self.mode) {
            (Some(k), GeometryMode::Frozen) => self.frozen(k, shape, pose, hs),
            (Some(k), GeometryMode::Refresh) => self.refresh(k, shape, pose, hs),
            (Some(k), _) => self.entries[k],
            (None, mode) => {
                let ov = shape_halfspace_overlap(shape, pose, hs);
                if matches!(mode, GeometryMode::Record | GeometryMode::Refresh) {
                    self.push(ov, pose, hs);
                }
                ov
            }
        }
    }

    /// Contact `index`'s entries start at the end of the list (recording).
    pub(super) fn register(&mut self, index: usize) {
        if self.contact_start.len() <= index {
            self.contact_start.resize(index + 1, usize::MAX);
        }
        self.contact_start[index] = self.entries.len();
    }

    /// Appends an overlap computed for a pair (recording).
    pub(super) fn push(&mut self, ov: Option<PlaneOverlap>, pose: &Isometry3<f64>, hs: &HalfSpace) {
        self.entries.push(ov);
        self.local_centroids.push(match ov {
            Some(ov) => pose.inverse_transform_point(&ov.centroid),
            None => Point3::origin(),
        });
        self.local_planes.push(local_plane(pose, hs));
    }

    /// Computes entry `k`'s overlap in full and remembers it.
    pub(super) fn compute(
        &mut self,
        k: usize,
        shape: &ConvexShape,
        pose: &Isometry3<f64>,
        hs: &HalfSpace,
    ) -> Option<PlaneOverlap> {
        let ov = shape_halfspace_overlap(shape, pose, hs);
        self.entries[k] = ov;
        if let Some(ov) = ov {
            self.local_centroids[k] = pose.inverse_transform_point(&ov.centroid);
            self.local_planes[k] = local_plane(pose, hs);
        }
        ov
    }

    /// The overlap of entry `k` in `Refresh` mode (see [`PATCH_REUSE`]).
    pub(super) fn refresh(
        &mut self,
        k: usize,
        shape: &ConvexShape,
        pose: &Isometry3<f64>,
        hs: &HalfSpace,
    ) -> Option<PlaneOverlap> {
        let Some((depth, deepest_point)) = shape_halfspace_depth(shape, pose, hs) else {
            self.entries[k] = None;
            return None;
        };
        if let Some(rec) = self.entries[k] {
            let (n0, c0) = self.local_planes[k];
            let (n, c) = local_plane(pose, hs);
            let moved = (c - c0).abs() + shape.bounding_radius() * (n - n0).norm();
            if moved <= PATCH_REUSE * rec.depth {
                return Some(PlaneOverlap {
                    depth,
                    volume: rec.volume,
                    area: rec.area,
                    centroid: pose * self.local_centroids[k],
                    deepest_point,
                });
            }
        }
        self.compute(k, shape, pose, hs)
    }

    /// The overlap of entry `k` (piece placed by `pose`, face `hs`) in `Frozen` mode.
    pub(super) fn frozen(
        &mut self,
        k: usize,
        shape: &ConvexShape,
        pose: &Isometry3<f64>,
        hs: &HalfSpace,
    ) -> Option<PlaneOverlap> {
        let (depth, deepest_point) = shape_halfspace_depth(shape, pose, hs)?;
        match self.entries[k] {
            Some(rec) => Some(PlaneOverlap {
                depth,
                volume: rec.volume,
                area: rec.area,
                centroid: pose * self.local_centroids[k],
                deepest_point,
            }),
            None => self.compute(k, shape, pose, hs),
        }
    }
}

/// The plane of `hs` in the frame of a piece placed by `pose`: unit normal and offset.
#[inline]
fn local_plane(pose: &Isometry3<f64>, hs: &HalfSpace) -> (Vector3<f64>, f64) {
    let n_world = hs.normal.into_inner();
    (
        pose.rotation.inverse_transform_vector(&n_world),
        hs.offset - n_world.dot(&pose.translation.vector),
    )
}
