//! The bounds of a case's `[wear]` table: the wear law's coefficients (eq. 3.8, 3.10-3.15; the
//! legacy appendix C code's C1-C3 act on N), the volume split and the wear mechanism beside
//! the law (`wear.mechanism`, what a diagnosis fits; the gap effect library gives each
//! parameter's source), with the law's peak coefficient held below severe adhesive wear.

use super::WearSpec;
use crate::field_error::FieldError;
use crate::parameters::{Bound, Bounded, FieldPath};
use crate::wear::allocation::VolumeSplit;
use crate::wear::law::WearLaw;
use crate::wear::mechanism::WearMechanism;

/// Largest wear-law cutoff pressure, Pa: 10 GPa, above the hardness of any engineering
/// alloy (7075-T73: 2 S_y = 870 MPa).
pub const MAX_CUTOFF_PRESSURE_PA: f64 = 1.0e10;
/// Largest wear coefficient any wear law may reach below its cutoff, m²/N: Archard's k/H for
/// severe adhesive wear (k about 1e-2) of the softest metals (H about 1e8 Pa). Table 4.3 at
/// its 870 MPa cutoff gives 6.1e-14.
pub const MAX_WEAR_COEFFICIENT_M2_PER_N: f64 = 1.0e-10;

const LEGACY_C1: Bound = Bound::new(
    0.0,
    1.0e-10,
    "",
    "the appendix code's C1 (Table 4.3: 2.4e-15); the law is kept only to reproduce the thesis",
);
const LEGACY_C2: Bound = Bound::new(
    0.0,
    100.0,
    "",
    "the appendix code's C2 (Table 4.3: 6.32; 0 gives no wear, as in the code)",
);
const LEGACY_C3: Bound = Bound::new(
    -1.0e-7,
    1.0e-7,
    "",
    "the appendix code's C3, scaled by 1e-3 in the code (Table 4.3: -9.5e-16)",
);
const C1: Bound = Bound::new(
    0.0,
    1.0e-10,
    "m²/N per Pa^(1/C2)",
    "wear grows with pressure (Table 4.3: C1 = 2.4e-15 > 0); at 1 Pa C1 is the wear \
     coefficient itself, which stays below 1e-10 m²/N (see coefficient_m2_per_n)",
);
const C2: Bound = Bound::new(
    0.5,
    100.0,
    "",
    "the pressure exponent 1/C2 lies between 0.01 and 2 (Table 4.3: C2 = 6.32); a coefficient \
     growing faster than pressure squared is no fitted wear law",
);
const C3: Bound = Bound::new(
    -1.0e-10,
    1.0e-10,
    "m²/N",
    "an offset of the wear coefficient, no larger than the largest coefficient (Table 4.3: \
     -9.5e-16)",
);
const CUTOFF_PRESSURE: Bound = Bound::new(
    1.0e5,
    MAX_CUTOFF_PRESSURE_PA,
    "Pa",
    "from atmospheric pressure (below it every contact is above the cutoff) to 10 GPa, above \
     the hardness of any engineering alloy (eq. 3.11: 2 S_y = 870 MPa for 7075)",
);
const ARCHARD_COEFFICIENT: Bound = Bound::new(
    0.0,
    MAX_WEAR_COEFFICIENT_M2_PER_N,
    "m²/N",
    "Archard's k/H: severe adhesive wear (k about 1e-2) on the softest metals (H about 1e8 Pa) \
     gives 1e-10 m²/N",
);
const SPEED_UNIT: Bound = Bound::new(
    1.0e-6,
    1.0,
    "m/s",
    "the exported slip-speed unit: µm/s to m/s (ADAMS: mm/s, 1e-3)",
);
const OUTPUT_UNIT: Bound = Bound::new(
    1.0e-27,
    1.0,
    "m³",
    "the appendix code's output unit: cubic nanometres to cubic metres (thesis: µm³, 1e-18)",
);
const FRACTION_TO_A: Bound = Bound::new(0.0, 1.0, "", "a share of the wear volume");
const RATIO: Bound = Bound::new(
    0.0,
    1000.0,
    "",
    "K above the cutoff as a multiple of K at it: up to the thousandfold jump from mild to \
     severe wear (Archard 1953; the library's wear_above_cutoff bound)",
);
const K_ADD: Bound = Bound::new(
    0.0,
    MAX_WEAR_COEFFICIENT_M2_PER_N,
    "m²/N",
    "an added k/H: severe adhesive wear (k about 1e-2) on the softest metals (H about 1e8 Pa) \
     gives 1e-10 m²/N, as for the Archard coefficient",
);
const MIN_PRESSURE: Bound = Bound::new(
    0.0,
    MAX_CUTOFF_PRESSURE_PA,
    "Pa",
    "a pressure threshold: no contact pressure exceeds 10 GPa, above any alloy's hardness",
);
const MIN_SLIP: Bound = Bound::new(
    0.0,
    100.0,
    "m/s",
    "a slip-speed threshold: a carried missile's shoes slide at mm/s to m/s",
);
const K_ENERGY: Bound = Bound::new(
    0.0,
    1.0e-11,
    "m³/J",
    "wear volume per joule of impact damping: dissipated-energy wear measures 1e-15 to 1e-13 \
     m³/J (Fouvry et al. 2003); Archard's range over H mu bounds it at 1.5e-11",
);
const MIN_NORMAL_SPEED: Bound = Bound::new(
    0.0,
    10.0,
    "m/s",
    "a normal-speed threshold of impact wear: rattling impacts reach cm/s to m/s",
);
const PRESSURE_RATIO_TO_YIELD: Bound = Bound::new(
    0.1,
    10.0,
    "",
    "a pressure threshold as a multiple of S_y: plastic flow starts near 1 and the hardness is \
     about 3 S_y (Tabor)",
);
const SHARE: Bound = Bound::new(
    0.0,
    1.0,
    "",
    "a share of the wear evaluated at the points' own pressures, 0 to all of it",
);
const BREAKTHROUGH_SLIP: Bound = Bound::new(
    0.0,
    1.0e9,
    "m",
    "the slip distance an anodic coating lasts: from new to beyond a million km of sliding",
);

/// The law's coefficients, and the largest coefficient the modified law reaches at or below
/// its cutoff held to [`MAX_WEAR_COEFFICIENT_M2_PER_N`] (the field bounds alone let
/// `C1 σ^(1/C2)` reach 1e10).
impl Bounded for WearLaw {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        match *self {
            WearLaw::Archard {
                coefficient_m2_per_n,
            } => at.number(
                "coefficient_m2_per_n",
                coefficient_m2_per_n,
                &ARCHARD_COEFFICIENT,
            ),
            WearLaw::Modified {
                c1,
                c2,
                c3,
                cutoff_pressure_pa,
            } => {
                at.number("c1", c1, &C1)?;
                at.number("c2", c2, &C2)?;
                at.number("c3", c3, &C3)?;
                at.number("cutoff_pressure_pa", cutoff_pressure_pa, &CUTOFF_PRESSURE)?;
                let peak = c1 * cutoff_pressure_pa.powf(1.0 / c2) + c3;
                if peak.is_finite() && peak <= MAX_WEAR_COEFFICIENT_M2_PER_N {
                    return Ok(());
                }
                at.field("c1", |at| {
                    Err(FieldError::new(
                        at.as_str(),
                        format!(
                            "gives a wear coefficient C1 σ^(1/C2) + C3 = {peak:e} m²/N at the \
                             cutoff {cutoff_pressure_pa:e} Pa; at most \
                             {MAX_WEAR_COEFFICIENT_M2_PER_N:e} m²/N (severe adhesive wear of \
                             the softest metals)"
                        ),
                    ))
                })
            }
            WearLaw::LegacyAppendix {
                c1,
                c2,
                c3,
                speed_unit_m_s,
                output_unit_m3,
            } => {
                at.number("c1", c1, &LEGACY_C1)?;
                at.number("c2", c2, &LEGACY_C2)?;
                at.number("c3", c3, &LEGACY_C3)?;
                at.number("speed_unit_m_s", speed_unit_m_s, &SPEED_UNIT)?;
                at.number("output_unit_m3", output_unit_m3, &OUTPUT_UNIT)
            }
        }
    }
}

impl Bounded for VolumeSplit {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        match *self {
            VolumeSplit::InverseHardness => Ok(()),
            VolumeSplit::Fixed { fraction_to_a } => {
                at.number("fraction_to_a", fraction_to_a, &FRACTION_TO_A)
            }
        }
    }
}

impl Bounded for WearMechanism {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        match *self {
            WearMechanism::WearAboveCutoff(t) => at.number("ratio", t.ratio, &RATIO),
            WearMechanism::ThirdBody(t) => {
                at.number("k_add_m2_per_n", t.k_add_m2_per_n, &K_ADD)?;
                at.number("min_pressure_pa", t.min_pressure_pa, &MIN_PRESSURE)?;
                at.number("min_slip_m_s", t.min_slip_m_s, &MIN_SLIP)
            }
            WearMechanism::ImpactWear(t) => {
                at.number("k_energy_m3_per_j", t.k_energy_m3_per_j, &K_ENERGY)?;
                at.number(
                    "min_normal_speed_m_s",
                    t.min_normal_speed_m_s,
                    &MIN_NORMAL_SPEED,
                )
            }
            WearMechanism::SevereWear(t) => {
                at.number("k_add_m2_per_n", t.k_add_m2_per_n, &K_ADD)?;
                at.number(
                    "pressure_ratio_to_yield",
                    t.pressure_ratio_to_yield,
                    &PRESSURE_RATIO_TO_YIELD,
                )
            }
            WearMechanism::LocalPressure(t) => at.number("share", t.share, &SHARE),
            WearMechanism::CoatingBreakthrough(t) => {
                at.number("k_add_m2_per_n", t.k_add_m2_per_n, &K_ADD)?;
                at.number(
                    "breakthrough_slip_m",
                    t.breakthrough_slip_m,
                    &BREAKTHROUGH_SLIP,
                )
            }
        }
    }
}

impl Bounded for WearSpec {
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError> {
        at.child("law", &self.law)?;
        at.child("volume_split", &self.volume_split)?;
        if let Some(mechanism) = &self.mechanism {
            at.child("mechanism", mechanism)?;
        }
        Ok(())
    }
}
