//! The impulse map of one contact's normal transient on a body that rests on other contacts
//! (issue 28: the frozen-rest map's missing floor, at the map's cost).
//!
//! [`super::impact_map`] freezes everything but the touching contact: on the rattle boxes that
//! misses 1.5-2.3 % of `∫N|v_slip| dt`, because the wall's friction presses the cube into the
//! floor while the wall arrests it (the body transient measured it: the floor's extra normal
//! impulse equals the wall's friction impulse along its normal, ratio 1.000). Here the body
//! translates in three directions in the touching contact's frame (axis 0 into the surface,
//! `ẇ`; axes 1 and 2 the slip plane, the map's `v_t`), with the map's effective masses
//! `diag(m_n, m_t, m_t)`, and each of its other pressed contacts is a rigid unilateral
//! support along its normal `n_j`: its normal force `N_j >= 0` is whatever keeps the body's
//! velocity along `n_j` constant (the constraint `n_j · v̇ = 0`, solved at every evaluation
//! together with the others'), and its own regularized Coulomb law acts on its slip
//! `s_j = (v + o_j) − n_j (n_j · (v + o_j))`, `o_j` the support point's velocity relative to the
//! touching point frozen over the transient (the frozen rotation's part):
//!
//! ```text
//! M v̇ = F_ext + (−N, f_t) + Σ_j N_j (n_j − μ_j(|s_j|) s_j/|s_j|),   n_j · v̇ = 0 (active j)
//! ```
//!
//! The touching contact's law, events and error control are the 1-D map's
//! (`impact_map::integrate`); with no support the equations and the steps are the
//! 1-D map's, bit for bit. docs/reference/models.md, "The supported impulse map", gives the
//! assumptions, the error bound and the measured error.

use super::friction::FrictionParams;
use super::impact::ImpactParams;
use super::impact_map::{
    integrate, start_state, ContactApproach, ImpactMap, ImpactMapError, ImpactMapSettings,
    NormalLaw, Piece, Scales, WallForces, VX, VY, W, WALL_DIM, WDOT,
};
use crate::field_error::FieldError;
use std::cell::Cell;

/// Most supports one map carries (the rattle box's cube on a wall has one, the floor; a
/// corner of the tube two).
pub const MAX_SUPPORTS: usize = 4;

/// A support's normal may not be closer to the touching contact's normal than this cosine:
/// a support along the impact direction would hold the body off the surface it hits.
const MAX_NORMAL_COSINE: f64 = 0.999;

/// One other pressed contact of the body, in the touching contact's frame (component 0 along
/// the approach, into the touched surface; 1 and 2 the map's slip axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support {
    /// Direction of the support's normal force on the body (out of the support), any length
    /// > 0 (normalized by the map).
    pub normal: [f64; 3],
    /// Velocity of the support point relative to the touching point, both relative to their
    /// surfaces, frozen over the transient, m/s (the body's rotation `ω × (r_j − r)`, frozen;
    /// zero for a translating body).
    pub velocity_offset: [f64; 3],
    /// The support's friction law (eq. 4.5).
    pub friction: FrictionParams,
}

/// One support's share of the transient.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupportShare {
    /// `∫N_j dt`, N·s.
    pub normal_impulse: f64,
    /// The support's friction impulse on the body, `−∫μ_j N_j s_j/|s_j| dt`, N·s (frame axes).
    pub friction_impulse: [f64; 3],
    /// `∫μ_j N_j |s_j| dt` >= 0, J.
    pub friction_dissipation: f64,
    /// `∫N_j |s_j| dt`, N·m (Archard's load times slip distance on the support).
    pub normal_force_slip_integral: f64,
    /// The support would have pulled (or held the body back from leaving it) in some
    /// evaluation and was let go there (its gap is not tracked: the map holds while every
    /// support stays pressed).
    pub lifted: bool,
}

/// What a supported transient hands back: the touching contact's map, each support's share,
/// the supports' work, the body's displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupportedImpactMap {
    /// The touching contact's map (its `external_work` is the external force's only).
    pub contact: ImpactMap,
    /// Per support, in the order given (the first `support_count` entries).
    pub supports: [SupportShare; MAX_SUPPORTS],
    /// Supports given.
    pub support_count: usize,
    /// Work of the supports on the body's translation that they do not dissipate:
    /// `∫Σ_j (N_j n_j·v − f_j·o_j) dt`, J (zero when every support starts at rest along its
    /// normal and the offsets are zero).
    pub support_work: f64,
    /// The body's displacement over the transient in the frame, m (component 0 is the end
    /// penetration).
    pub displacement: [f64; 3],
}

impl SupportedImpactMap {
    /// The supports' shares given.
    pub fn shares(&self) -> &[SupportShare] {
        &self.supports[..self.support_count]
    }

    /// Dissipated energy: damping, the contact's and the supports' friction, J.
    pub fn dissipated(&self) -> f64 {
        self.contact.damping_dissipation
            + self.contact.friction_dissipation
            + self
                .shares()
                .iter()
                .map(|s| s.friction_dissipation)
                .sum::<f64>()
    }

    /// `∫N|v_slip| dt` of the contact and its supports, N·m.
    pub fn normal_force_slip_integral(&self) -> f64 {
        self.contact.normal_force_slip_integral
            + self
                .shares()
                .iter()
                .map(|s| s.normal_force_slip_integral)
                .sum::<f64>()
    }
}

/// Why a supported map could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SupportedMapError {
    /// The touching contact's map refused its input or failed.
    #[error(transparent)]
    Map(#[from] ImpactMapError),
    /// More supports than [`MAX_SUPPORTS`].
    #[error("supports: {count} given, at most {max}")]
    TooManySupports {
        /// Supports given.
        count: usize,
        /// [`MAX_SUPPORTS`].
        max: usize,
    },
    /// A field of support `index` breaks its rule.
    #[error("support {index}: {error}")]
    Support {
        /// Index in the supports given.
        index: usize,
        /// The field and its rule.
        error: FieldError,
    },
}

impl SupportedMapError {
    /// The offending field's name, for input errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Map(e) => e.field(),
            Self::TooManySupports { .. } => Some("supports"),
            Self::Support { error, .. } => Some(&error.field),
        }
    }
}

/// A support checked and normalized.
#[derive(Clone, Copy)]
struct ActiveSupport {
    normal: [f64; 3],
    offset: [f64; 3],
    friction: FrictionParams,
    mu_slope_at_rest: f64,
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Support {
    /// Checks the normal (finite, not zero, not along the contact's normal), the offset
    /// (finite) and the friction law.
    fn checked(&self) -> Result<ActiveSupport, FieldError> {
        let length = dot(&self.normal, &self.normal).sqrt();
        if !(length.is_finite() && length > 0.0) {
            return Err(FieldError::new(
                "normal",
                format!("must be finite and not zero, got {:?}", self.normal),
            ));
        }
        let normal = self.normal.map(|x| x / length);
        if normal[0].abs() > MAX_NORMAL_COSINE {
            return Err(FieldError::new(
                "normal",
                "must not lie along the touching contact's normal (|cos| <= 0.999)",
            ));
        }
        if !self.velocity_offset.iter().all(|x| x.is_finite()) {
            return Err(FieldError::new("velocity_offset", "must be finite"));
        }
        self.friction.validate()?;
        Ok(ActiveSupport {
            normal,
            offset: self.velocity_offset,
            friction: self.friction,
            mu_slope_at_rest: self.friction.coefficient_derivative(0.0),
        })
    }
}

// State: the 1-D map's first components, then the supports' work, the slip-plane
// displacement, and per support its impulses and integrals.
const W_SUP: usize = WALL_DIM;
const DX: usize = WALL_DIM + 1;
const DY: usize = WALL_DIM + 2;
const SUPPORT_BASE: usize = WALL_DIM + 3;
// Per support: ∫N_j dt, the friction impulse (3), ∫μ N_j |s_j| dt, ∫N_j |s_j| dt.
const S_PN: usize = 0;
const S_PT: usize = 1;
const S_FRIC: usize = 4;
const S_SLIP: usize = 5;
const PER_SUPPORT: usize = 6;
const DIM: usize = SUPPORT_BASE + PER_SUPPORT * MAX_SUPPORTS;
type State = [f64; DIM];

struct SupportedContact<'a> {
    approach: &'a ContactApproach,
    law: NormalLaw<'a>,
    friction: &'a FrictionParams,
    mu_slope_at_rest: f64,
    supports: [Option<ActiveSupport>; MAX_SUPPORTS],
    count: usize,
    inverse_mass: [f64; 3],
    /// Bit j: support j was let go in some evaluation (rejected attempts included).
    lifted: Cell<usize>,
}

/// A support's friction at velocity `v`: the slip, `μ/|s|` (the rest slope at 0), `μ`, `|s|`.
#[inline]
fn support_slip(s: &ActiveSupport, v: &[f64; 3]) -> ([f64; 3], f64, f64, f64) {
    let u = [v[0] + s.offset[0], v[1] + s.offset[1], v[2] + s.offset[2]];
    let along = dot(&s.normal, &u);
    let slip = [
        u[0] - s.normal[0] * along,
        u[1] - s.normal[1] * along,
        u[2] - s.normal[2] * along,
    ];
    let speed = dot(&slip, &slip).sqrt();
    let mu = s.friction.coefficient(speed);
    let mu_per_speed = if speed > 0.0 {
        mu / speed
    } else {
        s.mu_slope_at_rest
    };
    (slip, mu_per_speed, mu, speed)
}

/// Solves the `k x k` system `a x = b` in place (partial pivoting); false when singular.
fn solve<const K: usize>(a: &mut [[f64; K]; K], b: &mut [f64; K], k: usize) -> bool {
    for col in 0..k {
        let pivot = (col..k)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        if !(a[pivot][col].abs() > 1e-12) {
            return false;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..k {
            let factor = a[row][col] / a[col][col];
            for c in col..k {
                a[row][c] -= factor * a[col][c];
            }
            b[row] -= factor * b[col];
        }
    }
    for row in (0..k).rev() {
        let mut acc = b[row];
        for c in row + 1..k {
            acc -= a[row][c] * b[c];
        }
        b[row] = acc / a[row][row];
    }
    true
}

impl SupportedContact<'_> {
    /// The supports' normal forces for the net force `force` without them (frame axes) and
    /// each support's force direction per unit normal force `g_j = n_j − (μ/|s|) s_j`: the
    /// largest set of supports whose forces are >= 0 with no other support driven into
    /// (`n_j·v̇ >= 0`), and that set as a bit mask.
    fn support_forces(
        &self,
        force: &[f64; 3],
        g: &[[f64; 3]; MAX_SUPPORTS],
    ) -> ([f64; MAX_SUPPORTS], usize) {
        let m = &self.inverse_mass;
        let accel = |f: &[f64; 3]| [m[0] * f[0], m[1] * f[1], m[2] * f[2]];
        let free = accel(force);
        let n = self.count;
        let full = (1usize << n) - 1;
        let normal = |j: usize| self.supports[j].as_ref().map(|s| s.normal);
        // Subsets by decreasing size: the first feasible one is taken.
        for size in (0..=n).rev() {
            for mask in (0..=full).rev().filter(|m| m.count_ones() as usize == size) {
                let mut idx = [0usize; MAX_SUPPORTS];
                let mut len = 0;
                for j in 0..n {
                    if mask & (1 << j) != 0 {
                        idx[len] = j;
                        len += 1;
                    }
                }
                let mut a = [[0.0; MAX_SUPPORTS]; MAX_SUPPORTS];
                let mut b = [0.0; MAX_SUPPORTS];
                for r in 0..len {
                    let n_r = normal(idx[r]).unwrap_or_default();
                    for c in 0..len {
                        a[r][c] = dot(&n_r, &accel(&g[idx[c]]));
                    }
                    b[r] = -dot(&n_r, &free);
                }
                if !solve(&mut a, &mut b, len) || b[..len].iter().any(|&x| x < 0.0) {
                    continue;
                }
                let mut forces = [0.0; MAX_SUPPORTS];
                for r in 0..len {
                    forces[idx[r]] = b[r];
                }
                let mut total = *force;
                for j in 0..n {
                    for i in 0..3 {
                        total[i] += forces[j] * g[j][i];
                    }
                }
                let a_total = accel(&total);
                let pushed_in = (0..n).any(|j| {
                    mask & (1 << j) == 0
                        && normal(j).is_some_and(|n_j| dot(&n_j, &a_total) < -1e-12)
                });
                if !pushed_in {
                    return (forces, mask);
                }
            }
        }
        ([0.0; MAX_SUPPORTS], 0)
    }

    /// The state's derivative on `piece`; a support let go in it is marked in `lifted`.
    fn derivative(&self, piece: Piece, y: &State) -> State {
        let a = self.approach;
        let (wdot, vx, vy) = (y[WDOT], y[VX], y[VY]);
        let (law, rest) = (&self.law, self.mu_slope_at_rest);
        let f = WallForces::at(law, self.friction, rest, piece, [y[W], wdot, vx, vy]);
        let [ftx, fty] = a.external_tangential_force;
        let mut total = [
            a.external_normal_force - f.normal,
            ftx + f.friction[0],
            fty + f.friction[1],
        ];
        let mut d = [0.0; DIM];
        if self.count > 0 {
            let v = [wdot, vx, vy];
            let mut g = [[0.0; 3]; MAX_SUPPORTS];
            let mut slips = [([0.0; 3], 0.0, 0.0, 0.0); MAX_SUPPORTS];
            for (j, s) in self.supports.iter().enumerate().take(self.count) {
                let Some(s) = s else { continue };
                slips[j] = support_slip(s, &v);
                let (slip, mu_per_speed, _, _) = slips[j];
                for i in 0..3 {
                    g[j][i] = s.normal[i] - mu_per_speed * slip[i];
                }
            }
            let (forces, active) = self.support_forces(&total, &g);
            let full = (1usize << self.count) - 1;
            if active != full {
                self.lifted.set(self.lifted.get() | (full & !active));
            }
            for (j, s) in self.supports.iter().enumerate().take(self.count) {
                let Some(s) = s else { continue };
                let n_j = forces[j];
                let (slip, mu_per_speed, mu_j, speed_j) = slips[j];
                let friction = slip.map(|x| -n_j * mu_per_speed * x);
                for i in 0..3 {
                    total[i] += n_j * s.normal[i] + friction[i];
                }
                let base = SUPPORT_BASE + PER_SUPPORT * j;
                d[base + S_PN] = n_j;
                d[base + S_PT..base + S_PT + 3].copy_from_slice(&friction);
                d[base + S_FRIC] = n_j * mu_j * speed_j;
                d[base + S_SLIP] = n_j * speed_j;
                d[W_SUP] += n_j * dot(&s.normal, &v) - dot(&friction, &s.offset);
            }
        }
        d[W] = wdot;
        d[WDOT] = total[0] / a.normal_mass;
        d[VX] = total[1] / a.tangential_mass;
        d[VY] = total[2] / a.tangential_mass;
        f.quadratures(a, wdot, [vx, vy], &mut d);
        d[DX] = vx;
        d[DY] = vy;
        d
    }
}

/// The map of one contact's transient on a body pressed onto `supports` (at most
/// [`MAX_SUPPORTS`]): integrates from first touch to separation or the time limit and
/// returns the contact's map, the supports' shares and work, and the body's displacement.
/// The approach's `external_*` forces are the body's other forces (gravity, the frame's
/// inertia, contacts that are not supports), without the supports'.
pub fn supported_impact_map(
    approach: &ContactApproach,
    supports: &[Support],
    impact: &ImpactParams,
    friction: &FrictionParams,
    settings: &ImpactMapSettings,
) -> Result<SupportedImpactMap, SupportedMapError> {
    approach.validate().map_err(ImpactMapError::Approach)?;
    impact.validate().map_err(ImpactMapError::Impact)?;
    friction.validate().map_err(ImpactMapError::Friction)?;
    settings.validate().map_err(ImpactMapError::Settings)?;
    if supports.len() > MAX_SUPPORTS {
        return Err(SupportedMapError::TooManySupports {
            count: supports.len(),
            max: MAX_SUPPORTS,
        });
    }
    let mut checked = [None; MAX_SUPPORTS];
    for (index, s) in supports.iter().enumerate() {
        checked[index] = Some(
            s.checked()
                .map_err(|error| SupportedMapError::Support { index, error })?,
        );
    }
    let contact = SupportedContact {
        approach,
        law: NormalLaw { impact },
        friction,
        mu_slope_at_rest: friction.coefficient_derivative(0.0),
        supports: checked,
        count: supports.len(),
        inverse_mass: [
            1.0 / approach.normal_mass,
            1.0 / approach.tangential_mass,
            1.0 / approach.tangential_mass,
        ],
        lifted: Cell::new(0),
    };
    let sc = Scales::of(approach, impact);
    let mut scale: State = sc.state();
    scale[DX..=DY].fill(sc.penetration);
    for j in 0..MAX_SUPPORTS {
        let base = SUPPORT_BASE + PER_SUPPORT * j;
        scale[base + S_PN..base + S_PT + 3].fill(sc.momentum);
    }
    let run = integrate(
        contact.law,
        settings,
        start_state(approach),
        &scale,
        sc.first_step(approach, impact),
        |piece, y| contact.derivative(piece, y),
    )?;
    let y = run.y;
    let lifted = contact.lifted.get();
    let mut shares = [SupportShare::default(); MAX_SUPPORTS];
    for (j, share) in shares.iter_mut().enumerate().take(contact.count) {
        let base = SUPPORT_BASE + PER_SUPPORT * j;
        *share = SupportShare {
            normal_impulse: y[base + S_PN],
            friction_impulse: [y[base + S_PT], y[base + S_PT + 1], y[base + S_PT + 2]],
            friction_dissipation: y[base + S_FRIC],
            normal_force_slip_integral: y[base + S_SLIP],
            lifted: lifted & (1 << j) != 0,
        };
    }
    Ok(SupportedImpactMap {
        contact: run.wall_map(),
        supports: shares,
        support_count: contact.count,
        support_work: y[W_SUP],
        displacement: [y[W], y[DX], y[DY]],
    })
}
