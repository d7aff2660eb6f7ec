//! The exactly integrated face contact (issue 27; docs/reference/models.md "Exact face contact"): a
//! rounded box's faces resolved by the continuum the contact-point lattice converges to,
//! integrated over each pressed polygon by a rule exact for the IMPACT law's polynomial
//! densities ([`crate::geometry::face_patch`]).
//!
//! Every quadrature node is a point of the per-material-point law
//! ([`Contact::evaluate_point`](super::Contact::evaluate_point)) with the plane's normal and
//! the node's share of the face: its force, damping and friction act at the node with the
//! node's own rates, so damping and friction do non-positive work node by node, and the
//! elastic resultants (force, torque, stored energy) over the face's extent are the exact
//! integrals. Beyond a bounded face's side, within the roundover radius, balls touch the
//! face's rounded-off edge ([`FacePatch::beyond_sides`]): the energy is continuous across the
//! side, so the region boundary terms of its gradient cancel and the elastic force is the
//! gradient of the stored energy up to the strips' quadrature error; a shoe sliding off a lip
//! unloads continuously.

use super::point::{friction_derivatives, penetration_rate, Lump, PointOutputs};
use super::reduced::ClosedPart;
use super::Contact;
use super::{JacobianScope, TrackLinearization};
use crate::geometry::{inner_box_faces, FacePatch, GradedStrip, PlacedFace, QuadratureOrder};
use crate::physics::body::BodyFrame;
use crate::physics::step::StepKind;
use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

/// How a contact resolves the faces of its rounded boxes (spheres are one point either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaceContact {
    /// Contact points on a lattice of `contact_points_per_edge` nodes per box edge
    /// ([`crate::geometry::lattice`]): converges like a trapezoid rule as the lattice refines.
    #[default]
    Lattice,
    /// Each face integrated over its pressed polygon with a Gauss rule exact for the IMPACT
    /// law's force, torque and stored energy (integer exponent), and over the strips beyond a
    /// bounded face's sides with 5 nodes across the edge and a rule along it graded by the
    /// density's smoothness ([`GradedStrip`]): the lattice's limit of infinitely many points
    /// (docs/reference/models.md "Exact face contact").
    Exact,
    /// The exact face contact with the clamp-free parts of each pressed polygon (the closing
    /// core and damping ramp) in closed form and their friction per part where its a-priori
    /// estimate is within the contact's tolerance, the exact contact's nodes elsewhere
    /// (`reduced.rs`; docs/reference/models.md "Reduced face law").
    Reduced,
}

/// Where the exact face contact evaluates friction. Cases always use [`FrictionRule::PerNode`];
/// the other rule is a measurement of the cheaper friction that issue 27's cost target would
/// need (`railwear-bench face-states` and `convergence --faces .. --friction-per-part`,
/// docs/journal/performance.md twentieth pass), with its own Jacobian (`Contact::end_lump`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrictionRule {
    /// Every quadrature node is a point of the per-material-point law, friction included.
    #[default]
    PerNode,
    /// Each part of a pressed polygon, and each strip beyond a bounded face's side, takes one
    /// friction force `−μ(|s_c|) N ŝ_c` at its nodes' load centre `p_c = Σ f_n p / N`, with `N =
    /// Σ f_n` and `s_c` the slip there in the plane of the load-weighted normal: passive
    /// (its power is `−μ N |s_c| <= 0`), exact where the slip is uniform over the part, and
    /// off by the slip's variation over the part (`ω × r`) elsewhere.
    PerPart,
}

/// Slices per strip beyond a bounded face's side (each with 5 nodes across the edge, and
/// along it the 5 of [`QuadratureOrder::ROUNDED_EDGE`] or fewer where
/// [`GradedStrip::ROUNDED_EDGE`] allows): the strip's integrand has a kink where `w = 0`
/// crosses it on a tilted face.
const ROUNDED_EDGE_SLICES: usize = 2;

/// Which inner faces take the side rules, by `|n_F · n|`, the cosine between the inner
/// face's normal and the face's: at or above the second value (within 60° of facing the
/// plane) the rules below, at or below the first (beyond 72.5°: a shoe head's ends and sides,
/// a box's side faces, pressed in slivers at most `w` high) the side rules
/// ([`QuadratureOrder::SIDE_EDGE`] on one slice for the strips beyond a bounded face's side,
/// [`SIDE_RAMP_RULE`] on the damping ramp), and between the two both, their node shares
/// blended by a cycloidal STEP. So the stored energy is continuous in the pose and every node
/// is a point of the per-point law with a positive share (passive node by node). A box always
/// has a face within 55° of facing the plane (its normals' cosines squared sum to 1). A side
/// face reaches the blend only when its piece tilts by 17.5° or more, which a shoe head in its
/// rail cannot. Where it is, the elastic force leaves out the blend's own gradient
/// `(U_fine − U_side) ∇λ`: zero on the ramps, whose side rule is exact for the stored
/// energy too, and a strip's quadrature difference on the strips.
const FACING: (f64, f64) = (0.3, 0.5);

/// A Newton matrix ([`JacobianScope::NewtonMatrix`]) leaves out the side faces' nodes (beyond
/// [`FACING`]'s 72.5°) of a piece pressed `w` deep when `w P <= SIDE_SHARE_MAX A`, with `A`
/// and `P` the area and perimeter of its inner face that most faces the plane (`w` is the
/// piece's depth below the face's unbounded plane, at least the pressed depth). The side
/// faces are then pressed in slivers at most `w` high along at most `P`: of a facing face
/// pressed whole they carry about `w P / ((e + 1) A)` of the load. A face pressed in part
/// (tilted, or over a lip's edge) gives them more, so what the matrix loses is measured as
/// Newton's contraction (docs/reference/models.md "The Newton matrix leaves out the side faces"); beyond
/// the gate (a degenerate or narrow face, a deep press) every node is linearized.
const SIDE_SHARE_MAX: f64 = 0.02;

/// The rule a Newton matrix takes a facing face's strip beyond a bounded face's side on
/// ([`JacobianScope::NewtonMatrix`]): one slice of 3 × 3 nodes (the side faces' strips' rule)
/// for the derivatives, where the force takes [`QuadratureOrder::ROUNDED_EDGE`] on
/// [`ROUNDED_EDGE_SLICES`] slices, graded along the edge ([`GradedStrip::ROUNDED_EDGE`]: 50
/// nodes on the fixed rule, 30 on smooth columns).
const STRIP_JACOBIAN_RULE: QuadratureOrder = QuadratureOrder::SIDE_EDGE;

/// The ramp rule of the faces that do not face the plane ([`FACING`]): 3 nodes across the
/// ramp instead of 5, for both its closing part ([`CLOSING_RAMP_RULE`]) and its separating
/// part ([`RAMP_RULE`]). Still exact for the stored energy, force and torque (`w` is affine
/// across the ramp, `w³` of degree 3 <= 5); only the damping's cycloid `STEP(w)` is sampled
/// by 3 nodes. There the ramp is the top `d` of a sliver at most `w` high; with it the
/// contact stays within 2e-3 of the gross load of the continuum at impact states
/// (tests/engine/face_contact.rs; 3.43e-4 measured, 3.42e-4 with 5 nodes).
const SIDE_RAMP_RULE: QuadratureOrder = QuadratureOrder {
    across: 2,
    along: 3,
};

/// The rule on the separating part of the damping ramp `w < d` of a pressed polygon, turned
/// so that its slices run across the ramp ([`FacePatch::aligned_with`] `w`): 5 nodes across,
/// on the STEP's cycloid in `w` (3 left 1e-3 of an impact's force, tests/engine/face_contact.rs
/// against the continuum), and along the ramp, where `w` is constant and the density
/// `max(0, k w^e + c STEP(w) ẇ)` is piecewise affine in the position with its kink where the
/// clamp cuts, 2 nodes on the pressing side of the kink (exact) and one on the clamped rest
/// ([`FacePatch::for_each_node_clamped`]).
const RAMP_RULE: QuadratureOrder = QuadratureOrder {
    across: 2,
    along: 5,
};

/// The rule on the closing part of the damping ramp (`ẇ >= 0`: no clamp), turned so that its
/// slices run across the ramp ([`FacePatch::aligned_with`] `w`): 5 nodes across, on the
/// cycloid, and 2 along the ramp, where `w` is constant and the force and torque densities are
/// affine and quadratic in the position (exact).
const CLOSING_RAMP_RULE: QuadratureOrder = QuadratureOrder {
    across: 2,
    along: 5,
};

/// The rule on the separating band where the force's clamp `max(0, k w^e + c ẇ)` may cut the
/// polygon along a curve, turned as the ramp: along the band, 2 nodes on the pressing side of
/// the clamp's kink (exact) and one on the clamped rest; across it 3 nodes, exact to degree 5
/// away from where the clamp's curve meets the band's sides (for `e = 2` the pressing
/// column's integral is a polynomial of degree 5 in `u` between those points).
const CLAMP_RULE: QuadratureOrder = QuadratureOrder {
    across: 2,
    along: 3,
};

/// How a part of a pressed polygon is integrated.
#[derive(Debug, Clone, Copy)]
enum PartRule {
    /// The patch rule for the exponent (exact for the polynomial densities).
    Patch,
    /// A fixed rule.
    Fixed(QuadratureOrder),
    /// A part turned along `w` whose force clamps to zero along a curve: the rule with its
    /// columns cut at the clamp ([`FacePatch::for_each_node_clamped`]).
    Clamped(QuadratureOrder),
    /// A part of the core (`w >= d`) where the clamp holds at every point
    /// (`ẇ <= −k w_max^e / c`): no force, so no friction; its stored energy and the clamp's
    /// dissipation are polynomials in `ξ`, integrated in closed form
    /// ([`Contact::unloaded_part`]) instead of at nodes.
    Unloaded,
}

impl PartRule {
    /// The rule of the same part on a face that does not face the plane ([`FACING`]), when
    /// it differs: the damping ramp's ([`SIDE_RAMP_RULE`]).
    fn on_side_face(self) -> Option<Self> {
        match self {
            PartRule::Fixed(CLOSING_RAMP_RULE) => Some(PartRule::Fixed(SIDE_RAMP_RULE)),
            PartRule::Clamped(RAMP_RULE) => Some(PartRule::Clamped(SIDE_RAMP_RULE)),
            _ => None,
        }
    }
}

/// Whether the side faces of an inner box of half extents `inner` placed by `pose`, pressed
/// `depth` deep against a plane of unit normal `normal`, are slivers a Newton matrix may leave
/// out ([`SIDE_SHARE_MAX`]): `depth P <= SIDE_SHARE_MAX A` for the inner face that most faces
/// the plane.
fn side_faces_are_slivers(
    inner: &Vector3<f64>,
    pose: &Isometry3<f64>,
    normal: &Vector3<f64>,
    depth: f64,
) -> bool {
    let local = pose.rotation.inverse_transform_vector(normal);
    let k = local.iamax();
    let (a, b) = (inner[(k + 1) % 3], inner[(k + 2) % 3]);
    // P = 4 (a + b) and A = 4 a b: the common factor 4 cancels.
    depth * (a + b) <= SIDE_SHARE_MAX * a * b
}

/// The share of the facing rules at `|n_F · n| = facing` ([`FACING`]): 1 within 60° of facing
/// the plane, 0 beyond 72.5°, a cycloidal STEP between.
fn facing_share(facing: f64) -> f64 {
    let (none, full) = FACING;
    if facing >= full {
        1.0
    } else if facing <= none {
        0.0
    } else {
        StepKind::Cycloidal.eval(facing, none, 0.0, full, 1.0)
    }
}

impl Contact {
    /// The normal-force density of a clamped part along its `u` (the part is turned along `w`:
    /// `w` depends on `u` alone, `ẇ` is affine): at `u`, the density at `v = 0` and its slope
    /// in `v`, zero where the part does not press. What
    /// [`FacePatch::for_each_node_clamped`] cuts at.
    pub(super) fn clamped_density<'a>(
        &'a self,
        part: &FacePatch,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        normal: &Vector3<f64>,
    ) -> impl Fn(f64) -> (f64, f64) + 'a {
        let depth = part.depth();
        let rate = penetration_rate(part, fa, fb, radius, normal);
        move |u: f64| {
            let w = depth.at([u, 0.0]);
            if w <= 0.0 {
                return (0.0, 0.0);
            }
            let (spring, damping) = self.impact.force_parts(w);
            let r0 = rate.at([u, 0.0]);
            (spring + damping * r0, damping * (rate.at([u, 1.0]) - r0))
        }
    }
    /// The pressed polygon `patch` cut where the per-point normal force
    /// `max(0, k w^e + c STEP(w, 0, 0, d, 1) ẇ)` changes form, each part with its rule (`None`:
    /// the patch rule). `w` and `ẇ` are affine in `ξ` (a rigid
    /// relative motion), so the cuts are straight: `w = d`, where the STEP ramp ends, and
    /// `ẇ = 0`. Where `w >= d` and `ẇ >= 0` the density is `k w^e + c ẇ`, a polynomial the patch
    /// rule integrates exactly (`e = 2`); the ramp (a cycloid in `w`) gets [`RAMP_RULE`] and
    /// the separating part (where `k w^e + c ẇ` may cross zero along a curve) [`CLAMP_RULE`],
    /// except where `ẇ <= −k w_max^e / c`: there every point is clamped to zero force, and the
    /// stored energy and the clamp's dissipation are integrated in closed form
    /// ([`PartRule::Unloaded`]). Every part's rule is exact for the
    /// elastic densities, so the stored energy and its gradient are the patch's exact integrals
    /// whatever the cuts.
    ///
    /// Each part goes to `push` as it is cut (up to five, in a fixed order), not through a
    /// returned array: a part is 360 bytes, and an array of them was copied twice per patch.
    fn damping_parts(
        &self,
        patch: &FacePatch,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        normal: &Vector3<f64>,
        push: &mut impl FnMut(&FacePatch, PartRule),
    ) {
        if self.impact.max_damping == 0.0 {
            push(patch, PartRule::Patch);
        } else {
            let rate = penetration_rate(patch, fa, fb, radius, normal);
            let (core, ramp) = patch.split(&patch.depth().minus(self.impact.full_damping_depth));
            if let Some(ramp) = ramp {
                let (closing, opening) = ramp.split(&rate);
                if let Some(closing) = closing {
                    // No clamp: along the ramp `w` is constant and the density affine.
                    push(
                        &closing.aligned_with(&patch.depth()),
                        PartRule::Fixed(CLOSING_RAMP_RULE),
                    );
                }
                if let Some(opening) = opening {
                    push(
                        &opening.aligned_with(&patch.depth()),
                        PartRule::Clamped(RAMP_RULE),
                    );
                }
            }
            if let Some(core) = core {
                let (closing, opening) = core.split(&rate);
                if let Some(closing) = closing {
                    push(&closing, PartRule::Patch);
                }
                if let Some(opening) = opening {
                    // Where ẇ <= −k w_max^e / c the force is clamped to zero at every point
                    // (w <= w_max on the part): only the stored energy and the clamp's
                    // dissipation, polynomials, are left, in closed form. The clamp's curve
                    // lies in the band between.
                    let (w_max, _) = opening.deepest();
                    let dead = -self.impact.elastic_force(w_max) / self.impact.max_damping;
                    let (band, clamped) = opening.split(&rate.minus(dead));
                    if let Some(band) = band {
                        push(
                            &band.aligned_with(&patch.depth()),
                            PartRule::Clamped(CLAMP_RULE),
                        );
                    }
                    if let Some(clamped) = clamped {
                        push(&clamped, PartRule::Unloaded);
                    }
                }
            }
        }
    }

    /// Evaluates the six faces of the inner box `inner` (half extents, m) of a rounded box of
    /// roundover `radius` placed by `pose` against `face`, into `out`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn evaluate_faces(
        &self,
        fa: &BodyFrame,
        fb: &BodyFrame,
        pose: &Isometry3<f64>,
        inner: &Vector3<f64>,
        radius: f64,
        depth: f64,
        face: &PlacedFace,
        out: &mut PointOutputs<'_, '_>,
    ) {
        let normal = face.plane.normal.into_inner();
        let reduced = self.face_contact == FaceContact::Reduced;
        let mut deepest: Option<(f64, Point3<f64>)> = None;
        let side_faces_unlinearized = out.scope == JacobianScope::NewtonMatrix
            && out.linearizing()
            && side_faces_are_slivers(inner, pose, &normal, depth);
        for (centre, axis_u, axis_v) in inner_box_faces(inner, pose) {
            // The share of the facing rules on this face ([`FACING`]).
            let fine = facing_share(axis_u.cross(&axis_v).normalize().dot(&normal).abs());
            // A Newton matrix leaves a side face's nodes out ([`JacobianScope::NewtonMatrix`]):
            // their derivatives are not taken, their forces are.
            let unlinearized = (fine == 0.0 && side_faces_unlinearized)
                .then(|| (out.linearizations.take(), out.moments.take()));
            let mut each = |part: &FacePatch, beyond_side: bool| {
                if beyond_side {
                    if reduced {
                        self.reduced_census.count_per_node();
                    }
                    self.integrate_strip(part, fine, fa, fb, radius, face, out);
                    return;
                }
                let patch = part;
                let d = patch.deepest();
                if deepest.is_none_or(|best| d.0 > best.0) {
                    deepest = Some(d);
                }
                let mut each_part = |part: &FacePatch, rule: PartRule| {
                    if reduced {
                        // The clamp-free parts in closed form where the friction estimate
                        // allows (`reduced.rs`); the rest at the nodes below.
                        let closed = match rule {
                            PartRule::Patch => Some(ClosedPart::Core),
                            PartRule::Fixed(CLOSING_RAMP_RULE) => Some(ClosedPart::Ramp),
                            _ => None,
                        };
                        match (closed, rule) {
                            (Some(kind), _) => {
                                if self.reduced_part(part, kind, fa, fb, radius, &normal, out) {
                                    return;
                                }
                            }
                            // The clamped parts' nodes with friction per part, on the rule
                            // of this face (not where two rules are blended).
                            (None, PartRule::Clamped(order)) if fine == 1.0 || fine == 0.0 => {
                                let order = match rule.on_side_face() {
                                    Some(PartRule::Clamped(side)) if fine == 0.0 => side,
                                    _ => order,
                                };
                                if self.reduced_clamped_part(part, order, fa, fb, radius, face, out)
                                {
                                    return;
                                }
                            }
                            (None, PartRule::Unloaded) => {}
                            (None, _) => self.reduced_census.count_per_node(),
                        }
                    }
                    if matches!(rule, PartRule::Unloaded)
                        && self.unloaded_part(part, fa, fb, radius, &normal, out)
                    {
                        return;
                    }
                    let integrate = |rule: PartRule, scale: f64, out: &mut PointOutputs<'_, '_>| {
                        self.integrate_part(part, rule, scale, fa, fb, radius, face, out)
                    };
                    match rule.on_side_face() {
                        Some(side) if fine < 1.0 => {
                            if fine > 0.0 {
                                integrate(rule, fine, out);
                            }
                            integrate(side, 1.0 - fine, out);
                        }
                        // `scale` 1: the nodes' shares unchanged, bit for bit.
                        _ => integrate(rule, 1.0, out),
                    }
                };
                self.damping_parts(patch, fa, fb, radius, &normal, &mut each_part);
            };
            // The strips beyond a side come only from a bounded face.
            FacePatch::for_each_part(centre, axis_u, axis_v, radius, face, &mut each);
            if let Some((linearizations, moments)) = unlinearized {
                out.linearizations = linearizations;
                out.moments = moments;
            }
        }
        // The track's penetration is the patch's deepest vertex (the exact maximum of the
        // linear `w`), not the deepest node.
        if let (Some((w, x)), true) = (deepest, out.sum.touching) {
            let p = x - normal * radius;
            let v_rel = fa.point_velocity(&p) - fb.point_velocity(&p);
            out.sum.penetration = w;
            out.sum.penetration_rate = -v_rel.dot(&normal);
            out.sum.deepest_point = p;
            out.sum.normal = normal;
        }
    }
}

impl Contact {
    /// Integrates `strip`, beyond a side of the bounded `face`, at its nodes: the facing
    /// rule's nodes with the share `fine` ([`FACING`]) and the side rule's with `1 − fine`.
    #[allow(clippy::too_many_arguments)]
    fn integrate_strip(
        &self,
        strip: &FacePatch,
        fine: f64,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        face: &PlacedFace,
        out: &mut PointOutputs<'_, '_>,
    ) {
        self.begin_lump(out);
        let visit = |x: Point3<f64>, share: f64, out: &mut PointOutputs<'_, '_>| {
            // A ball that does not reach the solid adds nothing (`evaluate_point` returns at
            // `w <= 0` before using anything): its normal is not taken.
            if let Some((distance, normal)) = face.signed_distance_within(&x, radius) {
                self.evaluate_point(fa, fb, &x, radius, share, distance, &normal, out);
            }
        };
        if fine > 0.0 {
            // `fine` is exactly 1 on a facing face: its nodes' shares unchanged. A Newton
            // matrix takes the strip's derivatives on the side rule's nodes instead
            // ([`STRIP_JACOBIAN_RULE`]); the force stays the fine rule's.
            let order = QuadratureOrder::ROUNDED_EDGE;
            // The damping's ramp `w < d`, where the graded rule cuts a column.
            let ramp = if self.impact.max_damping > 0.0 {
                self.impact.full_damping_depth
            } else {
                0.0
            };
            let coarse = out.scope == JacobianScope::NewtonMatrix
                && out.linearizing()
                && self.friction_rule == FrictionRule::PerNode;
            let kept = coarse.then(|| (out.linearizations.take(), out.moments.take()));
            strip.for_each_node_graded(
                order,
                ROUNDED_EDGE_SLICES,
                radius,
                ramp,
                GradedStrip::ROUNDED_EDGE,
                &mut |x, share| visit(x, fine * share, out),
            );
            if let Some((linearizations, moments)) = kept {
                out.linearizations = linearizations;
                out.moments = moments;
                // The derivatives alone (per-node friction: no lump), at the coarse nodes.
                let (mut energy, mut lump_nodes) = (0.0, Vec::new());
                let mut derivatives = out.derivatives_only(&mut energy, &mut lump_nodes);
                strip.for_each_node_sliced(STRIP_JACOBIAN_RULE, 1, &mut |x, share| {
                    visit(x, fine * share, &mut derivatives)
                });
                out.tangent = derivatives.tangent;
            }
        }
        if fine < 1.0 {
            let order = QuadratureOrder::SIDE_EDGE;
            strip.for_each_node_sliced(order, 1, &mut |x, share| {
                visit(x, (1.0 - fine) * share, out)
            });
        }
        self.end_lump(fa, fb, out);
    }

    /// Starts summing a part's normal loads for its friction at their load centre, when the
    /// contact's [`FrictionRule`] says so ([`Contact::end_lump`] ends it; nothing otherwise).
    fn begin_lump(&self, out: &mut PointOutputs<'_, '_>) {
        if self.friction_rule == FrictionRule::PerPart && self.friction.is_some() {
            out.lump = Some(Lump::default());
            out.lump_nodes.clear();
        }
    }

    /// The part's friction at its nodes' load centre ([`FrictionRule::PerPart`]; nothing
    /// unless [`Contact::begin_lump`] started a part), added to
    /// the track's sums as one more point; with derivatives, the part's nodes' records get the
    /// friction's share of `∂F/∂f_n` and go to the track's moments, with one more record at the
    /// load centre carrying the friction's slip derivative.
    ///
    /// Why this is the part's Jacobian but for the load centre's own motion in the slip,
    /// `[ω_rel]× δp_c` (tests/engine/face_friction_rule.rs bounds what that leaves): the
    /// friction `F = −μ(|s_c|) N ŝ_c` changes with each node's `f_n` by `−μ ŝ_c`, and its
    /// torque `p_c × F` by `p × (−μ ŝ_c)` at that node's own lever `p` (`N p_c = Σ f_n p`),
    /// which is what a node with `∂F/∂f_n = n − μ ŝ_c` at its own point contributes; the slip
    /// derivative `∂F/∂s_c` acts at `p_c`.
    fn end_lump(&self, fa: &BodyFrame, fb: &BodyFrame, out: &mut PointOutputs<'_, '_>) {
        let (Some(lump), Some(fr)) = (out.lump.take(), &self.friction) else {
            return;
        };
        let n = lump.normal_force;
        let normal = lump.normal.try_normalize(0.0);
        let (Some(normal), true) = (normal, n > 0.0) else {
            // No load: the records carry no friction share (their `f_n` and derivatives are 0).
            self.flush_lump_nodes(Vector3::zeros(), out);
            return;
        };
        let p = Point3::from(lump.moment / n);
        let v_rel = fa.point_velocity(&p) - fb.point_velocity(&p);
        let slip = v_rel - normal * v_rel.dot(&normal);
        let speed = slip.norm();
        let linearizing = out.linearizing();
        let mut share = Vector3::zeros();
        let mut mu_both = None;
        if speed > 0.0 {
            let both = fr.coefficient_with_derivative(speed);
            mu_both = Some(both);
            let ft = both.0 * n;
            share = slip * (-both.0 / speed);
            let force = share * n;
            out.sum.force += force;
            out.sum.torque_a += (p.coords - fa.position).cross(&force);
            out.sum.torque_b += (p.coords - fb.position).cross(&force);
            out.sum.friction_force += ft;
            out.sum.friction_power += ft * speed;
        }
        if linearizing {
            let tangent = Matrix3::identity() - normal * normal.transpose();
            let (_, dforce_dslip) =
                friction_derivatives(self.friction.as_ref(), &normal, &tangent, &slip, n, mu_both);
            self.flush_lump_nodes(share, out);
            let lin = TrackLinearization {
                body_a: self.body_a,
                body_b: self.body_b,
                deepest_point: p,
                point: p,
                centre: Point3::from(lump.centre / n),
                // The force itself is in the nodes' records, at their levers.
                force: Vector3::zeros(),
                normal,
                dfn_dw: 0.0,
                dfn_dwdot: 0.0,
                dforce_dfn: Vector3::zeros(),
                dforce_dslip,
            };
            out.push_linearization(&lin);
        }
    }

    /// Hands the part's node records to the track's moments (or list) with the friction's
    /// share `share = −μ_c ŝ_c` of `∂F/∂f_n` and of each node's force.
    fn flush_lump_nodes(&self, share: Vector3<f64>, out: &mut PointOutputs<'_, '_>) {
        // Taken out while `out` receives them; put back empty, its capacity kept.
        let mut nodes = std::mem::take(&mut *out.lump_nodes);
        for mut lin in nodes.drain(..) {
            let fn_mag = lin.force.dot(&lin.normal);
            lin.dforce_dfn += share;
            lin.force += share * fn_mag;
            out.push_linearization(&lin);
        }
        *out.lump_nodes = nodes;
    }

    /// Integrates `part` of a pressed polygon of `face` with `rule` at the nodes, each node's
    /// share times `scale` (1 but where two rules are blended, [`FACING`]).
    #[allow(clippy::too_many_arguments)]
    fn integrate_part(
        &self,
        part: &FacePatch,
        rule: PartRule,
        scale: f64,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        face: &PlacedFace,
        out: &mut PointOutputs<'_, '_>,
    ) {
        let normal = face.plane.normal.into_inner();
        let offset = face.plane.offset;
        self.begin_lump(out);
        let mut visit = |x: Point3<f64>, share: f64| {
            let distance = normal.dot(&x.coords) - offset;
            self.evaluate_point(fa, fb, &x, radius, scale * share, distance, &normal, out);
        };
        match rule {
            // An unloaded part whose exponent has no closed form: its nodes.
            PartRule::Patch | PartRule::Unloaded => {
                let order = QuadratureOrder::for_exponent(self.impact.exponent);
                part.for_each_node(order, &mut visit)
            }
            PartRule::Fixed(rule) => part.for_each_node(rule, &mut visit),
            PartRule::Clamped(rule) => {
                let sign = self.clamped_density(part, fa, fb, radius, &normal);
                part.for_each_node_clamped(rule, sign, &mut visit);
            }
        }
        self.end_lump(fa, fb, out);
    }

    /// The closed form of a part where the clamp holds at every point (no force, no
    /// friction): adds its stored energy `∫ β k w^(e+1)/(e+1)` and the clamp's dissipation
    /// `∫ β (f_n − k w^e) ẇ = −∫ β k w^e ẇ >= 0` (the per-point law's `damping_power`) with
    /// `β = dA_ξ / 4`, and marks the track touching (every point of the part penetrates).
    /// Both densities are polynomials of degree `e + 1` in `ξ` ([`crate::geometry::PolygonMoments`]); false
    /// (nothing added) unless `e` is 0, 1 or 2, for which they are exact: the caller then
    /// integrates the part at nodes.
    pub(super) fn unloaded_part(
        &self,
        part: &FacePatch,
        fa: &BodyFrame,
        fb: &BodyFrame,
        radius: f64,
        normal: &Vector3<f64>,
        out: &mut PointOutputs<'_, '_>,
    ) -> bool {
        let e = self.impact.exponent;
        let power = if e == 0.0 {
            0
        } else if e == 1.0 {
            1
        } else if e == 2.0 {
            2
        } else {
            return false;
        };
        let moments = part.moments();
        let depth = part.depth().about(moments.origin);
        let rate = penetration_rate(part, fa, fb, radius, normal).about(moments.origin);
        let mut factors = [depth; 3];
        let k = self.impact.stiffness;
        // ∫ w^(e+1) and ∫ w^e ẇ over the part (ξ units).
        let w_e1 = moments.product(&factors[..power + 1]);
        factors[power] = rate;
        let w_e_rate = moments.product(&factors[..power + 1]);
        *out.energy += 0.25 * k * w_e1 / (e + 1.0);
        out.sum.add_unloaded(-0.25 * k * w_e_rate);
        true
    }
}
