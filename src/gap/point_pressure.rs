//! The distribution of a contact track's point pressures (issue 26), kept per track and step
//! by `gap::tracks::TrackRecord` for the wear mechanisms at local pressure.
//!
//! A track's lumped pressure is the thesis' `sigma = N/A` (A the thesis
//! 2.5 area). Its contact points (`geometry::lattice`) carry the same face law resolved over
//! the face: point `i` with stiffness share `β_i` carries `N_i`. Its local pressure is the
//! lumped pressure scaled by how much more than its share the point carries:
//! `p_i = (N_i / β_i) (Σ_touching β_j) / A`. So a face pressed uniformly has `p_i = N/A` at
//! every point, and the share-weighted mean of the `p_i` is `N/A` in every configuration;
//! a tilted face loads its deeper points above the mean. The record keeps, per track and step,
//! the friction-work rate over μ, `Σ N_i |v_i|`, in pressure bins of 1/50 decade, each bin at
//! the work-weighted geometric mean of its points' pressures ([`PressureBin`]). A wear law
//! `K(p)` evaluated at a bin's mean instead of at each point differs by at most
//! `a² (ln 10 / 50)² / 8 = 2.6e-4 a²` relative within a bin, for `K ∝ p^a` (second order in
//! the bin's width; `a <= 2` for Table 4.3 gives <= 0.11 %), and a pressure threshold is
//! resolved to the bin's width (4.7 %).

use super::track_point::TrackPoint;
use crate::physics::contact::PointLoad;

pub use crate::wear::mechanism::PressureBin;

/// Pressure bins per decade of the point-pressure distribution.
pub const PRESSURE_BINS_PER_DECADE: f64 = 50.0;

/// Appends the point-pressure bins of track `tp` from its touching points `points` (see the
/// module docs): local pressure `p_i = (N_i / β_i) (Σ β_j) / A`, work rate `N_i |v_i|`, merged
/// in bins of 1/[`PRESSURE_BINS_PER_DECADE`] decade at the work-weighted geometric mean.
/// Points without slip carry no work and are left out.
pub(crate) fn push_pressure_bins<'a>(
    bins: &mut Vec<PressureBin>,
    tp: &TrackPoint,
    points: impl Iterator<Item = &'a PointLoad> + Clone,
) {
    let share: f64 = points.clone().map(|p| p.weight).sum();
    // (bin, Σ w, Σ w ln p), few per track: a linear search.
    let mut acc: Vec<(i64, f64, f64)> = Vec::new();
    let mut infinite = 0.0;
    for p in points {
        let w = p.normal_force * p.slip_speed;
        if !(w > 0.0) || !(p.weight > 0.0) {
            continue;
        }
        let pressure = if tp.area_m2 > 0.0 {
            p.normal_force / p.weight * share / tp.area_m2
        } else {
            f64::INFINITY
        };
        if !pressure.is_finite() {
            infinite += w;
            continue;
        }
        let ln_p = pressure.ln();
        let bin = (ln_p / std::f64::consts::LN_10 * PRESSURE_BINS_PER_DECADE).floor() as i64;
        match acc.iter_mut().find(|a| a.0 == bin) {
            Some(a) => {
                a.1 += w;
                a.2 += w * ln_p;
            }
            None => acc.push((bin, w, w * ln_p)),
        }
    }
    acc.sort_by_key(|a| a.0);
    bins.extend(acc.into_iter().map(|(_, w, wl)| PressureBin {
        pressure_pa: (wl / w).exp(),
        work_rate_w: w,
    }));
    if infinite > 0.0 {
        bins.push(PressureBin {
            pressure_pa: f64::INFINITY,
            work_rate_w: infinite,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The point pressures of a real contact: a rounded box (the rattle-box cube's size)
    /// sliding on a plane. Pressed flat, every point of the face is at the lumped N/A (one
    /// bin); tilted, the deeper edge carries more, so the bins straddle N/A, and in both the
    /// bins hold the whole `Σ N_i |v_i| = N v_slip`.
    #[test]
    fn point_pressures_of_a_sliding_box() {
        use crate::geometry::{ConvexShape, HalfSpace};
        use crate::physics::body::BodyFrame;
        use crate::physics::contact::Contact;
        use crate::physics::friction::FrictionParams;
        use crate::physics::impact::ImpactParams;
        use nalgebra::{Isometry3, UnitQuaternion, Vector3};
        let half = 0.0125;
        let shape = ConvexShape::rounded_box(Vector3::new(half, half, half), 5e-4).unwrap();
        let contact = Contact::new(
            "cube-ground",
            0,
            vec![(Isometry3::identity(), shape)],
            1,
            vec![HalfSpace::new(Vector3::z(), 0.0).unwrap()],
            ImpactParams::thesis_table_5_2(),
            Some(FrictionParams::thesis_table_5_2()),
        );
        let ground = BodyFrame {
            position: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        };
        for tilt in [0.0, 2e-4] {
            let cube = BodyFrame {
                position: Vector3::new(0.0, 0.0, half - 2e-6),
                rotation: UnitQuaternion::from_euler_angles(tilt, 0.0, 0.0),
                velocity: Vector3::new(0.05, 0.0, 0.0),
                angular_velocity: Vector3::zeros(),
            };
            let mut loads = Vec::new();
            let mut tracks = Vec::new();
            contact.evaluate_points(0, &[cube, ground], &mut |t| tracks.push(*t), &mut |p| {
                loads.push(*p)
            });
            assert_eq!(tracks.len(), 1, "tilt {tilt}");
            let t = tracks[0];
            let tp = TrackPoint {
                normal_force_n: t.normal_force,
                slip_speed_m_s: t.slip_speed,
                area_m2: t.area,
                ..TrackPoint::default()
            };
            let mut bins = Vec::new();
            push_pressure_bins(&mut bins, &tp, loads.iter());
            let work: f64 = bins.iter().map(|b| b.work_rate_w).sum();
            let nv = t.normal_force * t.slip_speed;
            assert!(
                (work - nv).abs() <= 1e-12 * nv,
                "tilt {tilt}: {work} vs {nv}"
            );
            let lumped = t.normal_force / t.area;
            if tilt == 0.0 {
                assert_eq!(bins.len(), 1);
                let p = bins[0].pressure_pa;
                assert!((p - lumped).abs() <= 1e-12 * lumped, "{p} vs {lumped}");
            } else {
                let lo = bins.first().unwrap().pressure_pa;
                let hi = bins.last().unwrap().pressure_pa;
                assert!(lo < lumped && hi > lumped, "{lo} {lumped} {hi}");
            }
        }
    }
}
