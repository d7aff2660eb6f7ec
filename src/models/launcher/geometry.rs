//! The launcher's derived geometry, all from its spec: the shoes' T-heads and necks, the latch
//! tooth and the missile placed in the rail frame at assembly, the leaf spring's tip and static
//! compression, the latch spring's installed length and the channel faces of the rail (eq.
//! 6.1-6.3 through [`LauncherDimensions`]).

use crate::analysis::rattle_space::{LauncherDimensions, RattleSpaceError};
use crate::models::spec::launcher::{LatchSpec, LauncherSpec, ShoeSpec};
use crate::models::spec::{PlanarFace, RoundedBoxSpec};
use crate::units;

impl ShoeSpec {
    /// The T-head as a rounded box in the missile frame: width `A`, thickness `K`, this length.
    pub fn head_box(&self, d: &LauncherDimensions) -> RoundedBoxSpec {
        let t = units::mm(d.k_shoe_mm);
        let b = self.head_base_in_missile_m;
        RoundedBoxSpec {
            centre_m: [b[0], b[1] + 0.5 * t, b[2]],
            half_extents_m: [0.5 * units::mm(d.a_shoe_mm), 0.5 * t, 0.5 * self.length_m],
            edge_radius_m: self.edge_radius_m,
        }
    }

    /// The neck as a rounded box in the missile frame: width `mean(N, O)`, height
    /// `mean(F-G, H-I, J-K, L-M)`, below the head.
    pub fn neck_box(&self, d: &LauncherDimensions) -> RoundedBoxSpec {
        let h = units::mm(d.mean_neck_height_mm());
        let b = self.head_base_in_missile_m;
        RoundedBoxSpec {
            centre_m: [b[0], b[1] - 0.5 * h, b[2]],
            half_extents_m: [
                0.5 * units::mm(d.mean_neck_width_mm()),
                0.5 * h,
                0.5 * self.length_m,
            ],
            edge_radius_m: self.edge_radius_m,
        }
    }

    /// Centre of the head's top face, missile frame, m (where the leaf spring bears).
    pub fn head_top_in_missile_m(&self, d: &LauncherDimensions) -> [f64; 3] {
        let b = self.head_base_in_missile_m;
        [b[0], b[1] + units::mm(d.k_shoe_mm), b[2]]
    }
}

impl LatchSpec {
    /// Tooth centre in the rail frame at assembly, m.
    pub fn tooth_centre_in_rail_m(&self) -> [f64; 3] {
        add3(self.com_in_rail_m, self.tooth.centre_m)
    }
}

fn add3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn dist3(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

impl LauncherSpec {
    /// Rattle space of the rail, eq. 6.1-6.3.
    pub fn rattle_space(&self) -> Result<f64, RattleSpaceError> {
        self.dimensions.rattle_space()
    }

    /// y of the chamber roof over the centreline, rail frame, m: lip top + mean(N_rail, Q_rail).
    pub fn chamber_roof_y_m(&self) -> f64 {
        self.rail.lip_top_y_m + units::mm(self.dimensions.mean_chamber_height_mm())
    }

    /// Missile centre of mass in the rail frame at assembly, m: the rear shoe's head rests on the
    /// lips (zero penetration), x = 0.
    pub fn missile_com_in_rail_m(&self) -> [f64; 3] {
        [
            -self.rear_shoe.head_base_in_missile_m[0],
            self.rail.lip_top_y_m - self.rear_shoe.head_base_in_missile_m[1],
            self.missile.com_z_in_rail_m,
        ]
    }

    /// Missile-frame point expressed in the rail frame at assembly, m.
    pub fn missile_to_rail_m(&self, p: [f64; 3]) -> [f64; 3] {
        add3(self.missile_com_in_rail_m(), p)
    }

    /// Leaf spring free tip, rail frame, m.
    pub fn leaf_spring_tip_in_rail_m(&self) -> [f64; 3] {
        [
            0.0,
            self.chamber_roof_y_m() - self.rear_leaf_spring.reach_below_roof_m,
            self.rear_leaf_spring.z_in_rail_m,
        ]
    }

    /// Leaf spring compression at assembly, m (> 0 engaged, < 0 a gap: not engaged when static).
    pub fn leaf_spring_static_compression_m(&self) -> f64 {
        let top = self.missile_to_rail_m(self.rear_shoe.head_top_in_missile_m(&self.dimensions));
        top[1] - self.leaf_spring_tip_in_rail_m()[1]
    }

    /// Latch spring length at assembly, m.
    pub fn latch_spring_installed_length_m(&self) -> f64 {
        dist3(
            self.latch_spring.point_on_rail_m,
            add3(self.latch.com_in_rail_m, self.latch_spring.point_on_latch_m),
        )
    }

    /// The channel faces the shoes, latch tooth and front pad can touch, rail frame (from
    /// `dimensions` and `rail`): lip tops (floor, +y), roof halves (-y, heights N_rail left and
    /// Q_rail right), chamber walls (width `B + A - mean(N, O)`, eq. 6.1), slot walls (width B)
    /// and the rail's bottom face (-y). Left is -x.
    pub fn rail_faces(&self) -> Vec<PlanarFace> {
        let d = &self.dimensions;
        let r = &self.rail;
        let half_b = 0.5 * units::mm(d.b_rail_mm);
        let half_w = 0.5 * units::mm(d.chamber_width_mm());
        let y0 = r.lip_top_y_m;
        let (hl, hr) = (units::mm(d.n_rail_mm), units::mm(d.q_rail_mm));
        let yb = y0 - r.lip_thickness_m;
        let zc = r.channel_centre_z_m;
        let hz = 0.5 * r.channel_length_m;
        let ez = [0.0, 0.0, 1.0];
        // Each face: tangent along z (half length = half the channel), width across.
        let face = |name: &str, centre: [f64; 3], normal: [f64; 3], half_width: f64| PlanarFace {
            name: name.to_string(),
            centre_m: centre,
            normal,
            tangent: ez,
            half_length_m: hz,
            half_width_m: half_width,
        };
        let lip_half = 0.5 * (half_w - half_b);
        let bottom_half = 0.5 * (r.bottom_half_width_m - half_b);
        vec![
            face(
                "lip_top_left",
                [-(half_b + lip_half), y0, zc],
                [0.0, 1.0, 0.0],
                lip_half,
            ),
            face(
                "lip_top_right",
                [half_b + lip_half, y0, zc],
                [0.0, 1.0, 0.0],
                lip_half,
            ),
            face(
                "roof_left",
                [-0.5 * half_w, y0 + hl, zc],
                [0.0, -1.0, 0.0],
                0.5 * half_w,
            ),
            face(
                "roof_right",
                [0.5 * half_w, y0 + hr, zc],
                [0.0, -1.0, 0.0],
                0.5 * half_w,
            ),
            face(
                "chamber_wall_left",
                [-half_w, y0 + 0.5 * hl, zc],
                [1.0, 0.0, 0.0],
                0.5 * hl,
            ),
            face(
                "chamber_wall_right",
                [half_w, y0 + 0.5 * hr, zc],
                [-1.0, 0.0, 0.0],
                0.5 * hr,
            ),
            face(
                "slot_wall_left",
                [-half_b, y0 - 0.5 * r.lip_thickness_m, zc],
                [1.0, 0.0, 0.0],
                0.5 * r.lip_thickness_m,
            ),
            face(
                "slot_wall_right",
                [half_b, y0 - 0.5 * r.lip_thickness_m, zc],
                [-1.0, 0.0, 0.0],
                0.5 * r.lip_thickness_m,
            ),
            face(
                "bottom_left",
                [-(half_b + bottom_half), yb, zc],
                [0.0, -1.0, 0.0],
                bottom_half,
            ),
            face(
                "bottom_right",
                [half_b + bottom_half, yb, zc],
                [0.0, -1.0, 0.0],
                bottom_half,
            ),
        ]
    }
}
