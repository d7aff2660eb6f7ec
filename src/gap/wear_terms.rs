//! The wear-law terms of the effect library (`gap::effects`, [`Acts::WearLaw`]
//! (super::effects::Acts::WearLaw)): each maps the wear coefficient K at a recorded sample to
//! the effective one, or adds a wear rate of a mechanism beyond sliding Archard at the lumped
//! pressure. Evaluated on recorded tracks (`gap::tracks`), never re-simulating; each at
//! magnitude 0 changes nothing, bit for bit.

use super::tracks::{WearSample, WearTerm};
use crate::wear::law::WearLaw;

/// (a) K above the cutoff = ratio x K just below it; unchanged below.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AboveCutoff {
    /// K above the cutoff / K at the cutoff.
    pub ratio: f64,
}

impl WearTerm for AboveCutoff {
    fn coefficient_m2_per_n(&self, k: f64, law: &WearLaw, s: &WearSample) -> f64 {
        let cutoff = law.cutoff_pressure_pa();
        if s.pressure_pa > cutoff && self.ratio != 0.0 {
            let k_cut = law.coefficient_m2_per_n(cutoff).unwrap_or(0.0);
            k + self.ratio * k_cut
        } else {
            k
        }
    }
}

/// (b) K + k_abr/H where pressure and slip speed reach their thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThirdBody {
    /// Added K, m²/N.
    pub k_add_m2_per_n: f64,
    /// Pressure threshold, Pa.
    pub min_pressure_pa: f64,
    /// Slip-speed threshold, m/s.
    pub min_slip_m_s: f64,
}

impl WearTerm for ThirdBody {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample) -> f64 {
        if self.k_add_m2_per_n != 0.0
            && s.pressure_pa >= self.min_pressure_pa
            && s.slip_speed_m_s >= self.min_slip_m_s
        {
            k + self.k_add_m2_per_n
        } else {
            k
        }
    }
}

/// (i) Impact wear: `k_E P_damp` added while `|ẇ| >= v_min` (all of it at `v_min = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactWear {
    /// Wear volume per joule of normal damping work, m³/J.
    pub k_energy_m3_per_j: f64,
    /// Normal speed below which damping work does not wear, m/s.
    pub min_normal_speed_m_s: f64,
}

impl WearTerm for ImpactWear {
    fn added_volume_rate_m3_s(&self, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_energy_m3_per_j != 0.0
            && s.penetration_rate_m_s.abs() >= self.min_normal_speed_m_s
        {
            self.k_energy_m3_per_j * s.damping_power_w
        } else {
            0.0
        }
    }
}

/// (j) Severe wear: `K_add Σ N_i |v_i|` over the contact points whose local pressure exceeds
/// `ratio Sy` (the lumped pressure when the points were not recorded).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SevereWear {
    /// Added K, m²/N (k_severe / H).
    pub k_add_m2_per_n: f64,
    /// Threshold as a multiple of the yield strength.
    pub pressure_ratio_to_yield: f64,
}

impl WearTerm for SevereWear {
    fn added_volume_rate_m3_s(&self, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_add_m2_per_n == 0.0 {
            return 0.0;
        }
        let threshold = self.pressure_ratio_to_yield * s.yield_strength_pa;
        let work: f64 = if s.points.is_empty() {
            if s.pressure_pa > threshold {
                s.normal_force_n * s.slip_speed_m_s
            } else {
                0.0
            }
        } else {
            s.points
                .iter()
                .filter(|b| b.pressure_pa > threshold)
                .map(|b| b.work_rate_w)
                .sum()
        };
        self.k_add_m2_per_n * work
    }
}

/// (k) Local-pressure Archard: a share of the lumped `K(N/A) N v` replaced by
/// `Σ K(p_i) N_i |v_i|` over the contact points (nothing without recorded points).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalPressure {
    /// Share of the wear at the points' own pressures, 0..1.
    pub share: f64,
}

impl WearTerm for LocalPressure {
    fn added_volume_rate_m3_s(&self, law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.share == 0.0 || s.points.is_empty() {
            return 0.0;
        }
        let k_of = |p: f64| law.coefficient_m2_per_n(p).unwrap_or(0.0);
        let local: f64 = s
            .points
            .iter()
            .map(|b| k_of(b.pressure_pa) * b.work_rate_w)
            .sum();
        let lumped = k_of(s.pressure_pa) * s.normal_force_n * s.slip_speed_m_s;
        self.share * (local - lumped)
    }
}

/// (l) Coating breakthrough: K + k_bare/H once the specimen's slip distance reaches the
/// breakthrough distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoatingBreakthrough {
    /// Added K, m²/N (k_bare / H).
    pub k_add_m2_per_n: f64,
    /// Slip distance at which the coating is worn through, m.
    pub breakthrough_slip_m: f64,
}

impl WearTerm for CoatingBreakthrough {
    fn coefficient_m2_per_n(&self, k: f64, _law: &WearLaw, s: &WearSample<'_>) -> f64 {
        if self.k_add_m2_per_n != 0.0 && s.slip_distance_m >= self.breakthrough_slip_m {
            k + self.k_add_m2_per_n
        } else {
            k
        }
    }
}
