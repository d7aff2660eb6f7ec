//! The dynamics effects of the library ((c)-(h), `super::effects`): their parameters, with
//! units, bounds, defaults and reasons, and the edits each makes to a case before a segment is
//! simulated, given the specimen's state at that segment.

use super::drive_edits::{
    add_cross_axis, filter_through_mount, resolved_excitation, set_excitation,
};
use super::GapError;
use crate::models::spec::CaseSpec;
use crate::parameters::parameter_struct;
use crate::physics::friction::FrictionParams;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a specimen has been through when a segment starts (or at its middle, for effects of
/// test time).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SpecimenState {
    /// Test time, h (the segment's middle).
    pub elapsed_h: f64,
    /// Slip distance accumulated before the segment, m.
    pub slip_distance_m: f64,
}

parameter_struct! {
    /// (c) `clearance_growth`'s parameters.
    pub struct ClearanceGrowthParameters = "clearance_growth" {
        opening_um_per_h {
            unit: "µm/h of clearance (tube side; launcher material-condition offset)",
            min: 0.0,
            max: 50.0,
            default: 0.0,
            reason: "case B's measured 97 mg/h (Table 5.3) is 34.6 mm³/h of 7075; spread over the cube's six faces it thins each by 9 µm/h (18 µm/h across a pair), localised wear a few times more: 50 µm/h bounds it",
        },
    }
}

parameter_struct! {
    /// (d) `friction_drift`'s parameters.
    pub struct FrictionDriftParameters = "friction_drift" {
        delta_mu {
            unit: "1",
            min: -0.1,
            max: 0.6,
            default: 0.0,
            reason: "anodize worn through leaves bare 7075 on 7075, dry mu 0.6-1.0 (ASM Handbook 18); polishing lowers mu a little; -0.1 keeps mu_d of Table 5.2 (0.166) positive",
        },
        slip_scale_m {
            unit: "m",
            min: 1.0,
            max: 1.0e4,
            default: 100.0,
            reason: "estimate: running-in completes within 1-1000 m of sliding for light loads (Blau, Friction and Wear Transitions, 1989)",
        },
    }
}

parameter_struct! {
    /// (e) `fixture_compliance`'s parameters.
    pub struct FixtureComplianceParameters = "fixture_compliance" {
        natural_period_ms {
            unit: "ms (1 / mount natural frequency; 0 = rigid)",
            min: 0.0,
            max: 20.0,
            default: 0.0,
            reason: "fixtures are designed with their first resonance above the test band; a bolted tube on a head expander may come down to 50-200 Hz (5-20 ms)",
        },
        damping_ratio {
            unit: "1",
            min: 0.01,
            max: 0.3,
            default: 0.05,
            reason: "bolted aluminium joints: 1-5 % of critical, elastomer mounts up to 30 % (Harris' Shock and Vibration Handbook)",
        },
    }
}

parameter_struct! {
    /// (f) `cross_axis`'s parameters.
    pub struct CrossAxisParameters = "cross_axis" {
        share {
            unit: "1 (cross-axis amplitude / drive amplitude, each other axis)",
            min: 0.0,
            max: 0.3,
            default: 0.0,
            reason: "shaker acceptance limits cross-axis motion to 10-30 % of the drive axis (IEST-RP-DTE012, MIL-STD-810G 514.6 Annex A)",
        },
        phase_deg {
            unit: "degree",
            min: -180.0,
            max: 180.0,
            default: 0.0,
            reason: "rocking of the armature gives in-phase or anti-phase cross motion; any phase allowed",
        },
    }
}

parameter_struct! {
    /// (g) `sharp_edges`'s parameters.
    pub struct SharpEdgesParameters = "sharp_edges" {
        roundover_reduction {
            unit: "1 (fraction of the nominal roundover removed)",
            min: 0.0,
            max: 0.9,
            default: 0.0,
            reason: "thesis 5.4 adds a 0.02 in roundover \"to better model the real fixture\" and notes contact area and pressure depend on it; machined edges range from sharp to the nominal break",
        },
    }
}

parameter_struct! {
    /// (h) `preload_loss`'s parameters.
    pub struct PreloadLossParameters = "preload_loss" {
        loss {
            unit: "1 (fraction of the preload lost)",
            min: 0.0,
            max: 1.0,
            default: 0.0,
            reason: "coil and leaf springs relax by stress relaxation and set; 1 = fully lost (SPEC 7: spring preload loss or non-engagement)",
        },
    }
}

impl ClearanceGrowthParameters {
    pub(super) fn apply(&self, case: &mut CaseSpec, state: &SpecimenState) {
        let opening_m = self.opening_um_per_h * 1e-6 * state.elapsed_h;
        if let Some(rb) = case.rattle_box.as_mut() {
            rb.tube_inner_side_m += opening_m;
            rb.case = format!("{}-worn", rb.case);
        } else if let Some(l) = case.launcher.as_mut() {
            // A positive material-condition offset shrinks the shoes and opens the rail by the
            // same amount (analysis::rattle_space).
            l.dimensions = l.dimensions.with_material_condition(opening_m * 1e3);
        }
    }
}

impl FrictionDriftParameters {
    pub(super) fn apply(&self, case: &mut CaseSpec, state: &SpecimenState) {
        let d = self.delta_mu * (1.0 - (-state.slip_distance_m / self.slip_scale_m).exp());
        let shift = |f: &mut FrictionParams| {
            f.mu_static += d;
            f.mu_dynamic += d;
        };
        if let Some(rb) = case.rattle_box.as_mut() {
            shift(&mut rb.friction);
        }
        if let Some(l) = case.launcher.as_mut() {
            shift(&mut l.friction);
        }
    }
}

impl FixtureComplianceParameters {
    pub(super) fn apply(
        &self,
        case: &mut CaseSpec,
        configs_dir: &Path,
        field: &str,
    ) -> Result<(), GapError> {
        let spec = resolved_excitation(case, configs_dir, field)?;
        let period = self.natural_period_ms * 1e-3;
        let spec = filter_through_mount(spec, period, self.damping_ratio, field)?;
        set_excitation(case, &spec, field)
    }
}

impl CrossAxisParameters {
    pub(super) fn apply(
        &self,
        case: &mut CaseSpec,
        configs_dir: &Path,
        field: &str,
    ) -> Result<(), GapError> {
        let spec = resolved_excitation(case, configs_dir, field)?;
        let spec = add_cross_axis(spec, self.share, self.phase_deg, field)?;
        set_excitation(case, &spec, field)
    }
}

impl SharpEdgesParameters {
    pub(super) fn apply(&self, case: &mut CaseSpec) {
        let keep = 1.0 - self.roundover_reduction;
        if let Some(rb) = case.rattle_box.as_mut() {
            rb.edge_radius_m *= keep;
        }
        if let Some(l) = case.launcher.as_mut() {
            l.mid_shoe.edge_radius_m *= keep;
            l.rear_shoe.edge_radius_m *= keep;
            l.front_pad.edge_radius_m *= keep;
            l.latch.tooth.edge_radius_m *= keep;
            if let Some(p) = l.mid_shoe.protrusion.as_mut() {
                p.edge_radius_m *= keep;
            }
        }
    }
}

impl PreloadLossParameters {
    pub(super) fn apply(&self, case: &mut CaseSpec) {
        let keep = 1.0 - self.loss;
        if let Some(l) = case.launcher.as_mut() {
            l.latch_spring.preload_n *= keep;
            l.rear_leaf_spring.preload_n *= keep;
        }
    }
}
