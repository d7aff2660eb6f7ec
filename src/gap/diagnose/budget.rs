//! The energy budget of "where" (issue 26 item 2): per test and contact, the work the nominal
//! model does by kind (sliding friction, normal impact damping) and the integrals each wear
//! mechanism scales, and per weighed component, the coefficient each mechanism would need to
//! produce the measured wear, against its literature range. It shows, before any fit, which
//! mechanisms could produce the gap at all.
//!
//! Every mechanism's wear is linear in its coefficient κ: a contact `c` wears `κ D_c` (m³) with
//! `D_c` the mechanism's driver over the test (e.g. the damping work for impact wear), and a
//! component `b` loses `Σ_c κ D_c q_cb` (mg) with `q_cb` the mass charged to `b` per m³ worn at
//! `c` (the case's volume split and density). So the coefficient that reproduces a measured
//! mass `M_b` is `κ = M_b / Σ_c D_c q_cb`, exactly, for the nominal model's motion.

use crate::gap::tracks::{ContactWork, SlipHistory};
use crate::gap::window::WindowRun;
use crate::gap::GapError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// One increment's work and charge, summed over its segments (each scaled to the test time it
/// stands for).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct IncrementWork {
    /// Contact names, in model order.
    pub contact_names: Vec<String>,
    /// Per contact: work and mechanism drivers over the increment.
    pub contacts: Vec<ContactWork>,
    /// Per contact: mass charged to each body per m³ worn there, mg/m³.
    pub charge_mg_per_m3: Vec<BTreeMap<String, f64>>,
    /// Indentation hardness of the softer surface, Pa.
    pub hardness_pa: f64,
    /// Yield strength, Pa.
    pub yield_strength_pa: f64,
    /// Whether the contact points' pressures were recorded (local pressures available).
    pub point_pressures: bool,
    /// Work the drive delivered, J.
    #[serde(default)]
    pub drive_j: f64,
    /// Change of the mechanical energy over the windows, scaled like the work, J.
    #[serde(default)]
    pub energy_change_j: f64,
}

impl IncrementWork {
    /// The work of an increment's segments.
    pub fn of(segments: &[(Arc<WindowRun>, SlipHistory)]) -> Result<Self, GapError> {
        let mut out = Self::default();
        for (run, h) in segments {
            let work = run.record.work_by_contact(&run.law);
            if out.contacts.is_empty() {
                out.contacts = vec![ContactWork::default(); work.len()];
                out.contact_names = run.contact_names();
                out.charge_mg_per_m3 = run.charge_mg_per_m3()?;
                out.hardness_pa = run.hardness_pa;
                out.yield_strength_pa = run.yield_strength_pa;
                out.point_pressures = run.record.has_point_pressures();
            }
            out.drive_j += h.time_scale * run.record.drive_work_j();
            out.energy_change_j += h.time_scale * run.record.energy_change_j();
            for (acc, w) in out.contacts.iter_mut().zip(&work) {
                acc.add_scaled(w, h.time_scale);
            }
        }
        Ok(out)
    }
}

/// A wear mechanism of the budget: what drives it and its literature range.
#[derive(Debug, Clone, Copy)]
pub struct Mechanism {
    /// Name (a library effect's where there is one).
    pub name: &'static str,
    /// Its coefficient, with unit.
    pub coefficient: &'static str,
    /// Unit of the coefficient.
    pub unit: &'static str,
    /// Literature range of the coefficient (low, high).
    pub range: (f64, f64),
    /// Why this range.
    pub reason: &'static str,
    /// The driver of contact `c`, in the coefficient's reciprocal unit times m³.
    driver: fn(&ContactWork, f64) -> f64,
}

/// The mechanisms of the budget.
pub const MECHANISMS: &[Mechanism] = &[
    Mechanism {
        name: "sliding_archard",
        coefficient: "K",
        unit: "m²/N",
        range: (7.6e-17, 7.6e-12),
        reason: "dimensionless Archard k of 1e-7 (mild, oxide- or anodize-protected) to 1e-2 (severe adhesive) over H = 1.32 GPa (Archard 1953; Hutchings 1992); the pair's own Table 4.3 is far lower (6.1e-14 at its 870 MPa cutoff, issue 26)",
        driver: |w, _| w.sliding_n_m,
    },
    Mechanism {
        name: "friction_energy",
        coefficient: "alpha (volume per joule of friction work)",
        unit: "m³/J",
        range: (1.5e-15, 1.5e-11),
        reason: "Fouvry's dissipated-energy coefficient: 1e-15 to 1e-13 for steels and coatings in fretting (Fouvry et al., Wear 2003); k/(H mu) with k = 1e-6..1e-2, H = 1.32 GPa, mu = 0.5 for aluminium alloys",
        driver: |w, _| w.friction_j,
    },
    Mechanism {
        name: "impact_wear",
        coefficient: "k_E (volume per joule of normal damping work)",
        unit: "m³/J",
        range: (1.5e-15, 1.5e-11),
        reason: "the friction-energy range applied to the normal impacts' dissipated energy (Engel, Impact Wear of Materials, 1976: the same fatigue and plastic mechanisms); the library's bound is its top",
        driver: |w, _| w.damping_j,
    },
    Mechanism {
        name: "severe_wear",
        coefficient: "k_severe (dimensionless, at contact points above Sy)",
        unit: "1",
        range: (1.0e-4, 1.0e-2),
        reason: "severe adhesive or plastic wear of aluminium alloys (Archard 1953; Lim & Ashby 1987)",
        driver: |w, h| w.sliding_above_yield_n_m / h,
    },
    Mechanism {
        name: "third_body",
        coefficient: "k_abrasive (dimensionless, all sliding)",
        unit: "1",
        range: (5.0e-4, 1.0e-2),
        reason: "three-body abrasion (Hutchings 1992; Rabinowicz 1995), up to 1e-2 for sharp sand",
        driver: |w, h| w.sliding_n_m / h,
    },
];

/// One contact's work over a test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactBudget {
    /// Contact name.
    pub contact: String,
    /// Friction work, J.
    pub friction_j: f64,
    /// Normal (IMPACT) damping work, J.
    pub damping_j: f64,
    /// Damping work over friction work.
    pub damping_to_friction: f64,
    /// `∫ N v_slip dt`, N·m.
    pub sliding_n_m: f64,
    /// Share of it at contact points above the yield strength.
    pub share_above_yield: f64,
    /// Wear of the case's law at the lumped pressure N/A (the model's), mm³.
    pub lumped_archard_mm3: f64,
    /// The same law at the contact points' own pressures, mm³.
    pub local_archard_mm3: f64,
}

/// The coefficient a mechanism needs for one component's measured wear.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Needed {
    /// Component (`cube`).
    pub component: String,
    /// Mechanism (see [`MECHANISMS`]).
    pub mechanism: String,
    /// Coefficient, with what it is.
    pub coefficient: String,
    /// Unit.
    pub unit: String,
    /// Needed value (None: the mechanism has no driver in this test).
    pub value: Option<f64>,
    /// Literature range.
    pub range: [f64; 2],
    /// `within`, `above` or `below` the range, or `no_driver`.
    pub verdict: String,
}

/// One test's budget.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TestBudget {
    /// Test id.
    pub test: String,
    /// Test time summed over its increments, h.
    pub hours: f64,
    /// Work the drive delivered to the model over the test, J (it leaves as the contacts'
    /// friction and damping work and the force elements' dissipation).
    pub drive_j: f64,
    /// Change of the model's mechanical energy over its windows, scaled like the work, J:
    /// `drive = friction + damping + elements + change` closes the account.
    pub energy_change_j: f64,
    /// Per contact.
    pub contacts: Vec<ContactBudget>,
    /// Per weighed component and mechanism.
    pub needed: Vec<Needed>,
}

/// The energy budget of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct EnergyBudget {
    /// Per test.
    pub tests: Vec<TestBudget>,
    /// What the mechanisms' ranges rest on, one line each.
    pub ranges: Vec<String>,
    /// How the budget is computed, and what it does not hold.
    pub notes: Vec<String>,
}

/// The budget of `tests` (id, hours, per increment work) against the measured masses
/// `measured` (test id, component, mg summed over the increments weighed).
pub fn energy_budget(
    tests: &[(String, f64, Vec<IncrementWork>)],
    measured: &BTreeMap<(String, String), f64>,
) -> EnergyBudget {
    let mut out = EnergyBudget {
        ranges: MECHANISMS
            .iter()
            .map(|m| {
                format!(
                    "{} {} [{:.1e}, {:.1e}] {}: {}",
                    m.name, m.coefficient, m.range.0, m.range.1, m.unit, m.reason
                )
            })
            .collect(),
        notes: vec![
            "work and drivers are the nominal model's, summed over each test's increments (each increment's window scaled to its duration); the drive's work is the trapezoid of its power over the window's steps".into(),
            "needed coefficient = measured mass / (Σ over contacts of the mechanism's driver x the mass charged to the component per m³ worn there): each mechanism alone, on the nominal motion".into(),
        ],
        ..EnergyBudget::default()
    };
    for (test, hours, incs) in tests {
        let Some(first) = incs.first() else { continue };
        let n = first.contacts.len();
        let mut total = vec![ContactWork::default(); n];
        for inc in incs {
            for (acc, w) in total.iter_mut().zip(&inc.contacts) {
                acc.add_scaled(w, 1.0);
            }
        }
        let contacts = total
            .iter()
            .enumerate()
            .map(|(c, w)| ContactBudget {
                contact: first.contact_names.get(c).cloned().unwrap_or_default(),
                friction_j: w.friction_j,
                damping_j: w.damping_j,
                damping_to_friction: ratio(w.damping_j, w.friction_j),
                sliding_n_m: w.sliding_n_m,
                share_above_yield: ratio(w.sliding_above_yield_n_m, w.sliding_n_m),
                lumped_archard_mm3: w.lumped_archard_m3 * 1e9,
                local_archard_mm3: w.local_archard_m3 * 1e9,
            })
            .collect();
        let mut needed = Vec::new();
        for ((t, component), &mass_mg) in measured {
            if t != test {
                continue;
            }
            for m in MECHANISMS {
                let per_unit: f64 = total
                    .iter()
                    .enumerate()
                    .map(|(c, w)| {
                        let q = first
                            .charge_mg_per_m3
                            .get(c)
                            .and_then(|q| q.get(component))
                            .copied()
                            .unwrap_or(0.0);
                        (m.driver)(w, first.hardness_pa) * q
                    })
                    .sum();
                let value = (per_unit > 0.0).then(|| mass_mg / per_unit);
                let verdict = match value {
                    None => "no_driver",
                    Some(v) if v > m.range.1 => "above",
                    Some(v) if v < m.range.0 => "below",
                    Some(_) => "within",
                };
                needed.push(Needed {
                    component: component.clone(),
                    mechanism: m.name.into(),
                    coefficient: m.coefficient.into(),
                    unit: m.unit.into(),
                    value,
                    range: [m.range.0, m.range.1],
                    verdict: verdict.into(),
                });
            }
        }
        out.tests.push(TestBudget {
            test: test.clone(),
            hours: *hours,
            drive_j: incs.iter().map(|i| i.drive_j).sum(),
            energy_change_j: incs.iter().map(|i| i.energy_change_j).sum(),
            contacts,
            needed,
        });
    }
    out
}

impl EnergyBudget {
    /// The budget as text: per test and contact the work by kind, then per component the
    /// coefficient each mechanism needs against its range.
    pub fn table(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        if self.tests.is_empty() {
            return s;
        }
        let _ = writeln!(
            s,
            "energy budget (nominal model, per test):\n  {:<10} {:<16} {:>12} {:>12} {:>9} {:>9} {:>13} {:>13}",
            "test", "contact", "friction J", "damping J", "damp/fric", ">Sy share", "Archard mm³", "local mm³"
        );
        for t in &self.tests {
            let _ = writeln!(
                s,
                "  {:<10} {:<16} drive work {:.4e} J",
                t.test, "(all)", t.drive_j
            );
            for c in &t.contacts {
                let _ = writeln!(
                    s,
                    "  {:<10} {:<16} {:>12.4e} {:>12.4e} {:>9.2} {:>9.3} {:>13.4e} {:>13.4e}",
                    t.test,
                    c.contact,
                    c.friction_j,
                    c.damping_j,
                    c.damping_to_friction,
                    c.share_above_yield,
                    c.lumped_archard_mm3,
                    c.local_archard_mm3
                );
            }
        }
        let _ = writeln!(
            s,
            "coefficient needed for the measured wear (each mechanism alone) vs literature range:\n  {:<10} {:<10} {:<16} {:>11} {:>21} verdict",
            "test", "component", "mechanism", "needed", "range"
        );
        for t in &self.tests {
            for n in &t.needed {
                let value = n
                    .value
                    .map_or_else(|| "-".to_string(), |v| format!("{v:.2e}"));
                let _ = writeln!(
                    s,
                    "  {:<10} {:<10} {:<16} {:>11} {:>21} {} ({})",
                    t.test,
                    n.component,
                    n.mechanism,
                    value,
                    format!("[{:.1e}, {:.1e}]", n.range[0], n.range[1]),
                    n.verdict,
                    n.unit
                );
            }
        }
        s
    }
}

fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One contact charging 2 mg per mm³ to the cube: each mechanism's needed coefficient is
    /// the measured mass over its driver times the charge, by hand.
    #[test]
    fn needed_coefficients_are_mass_over_driver() {
        let work = ContactWork {
            friction_j: 10.0,
            damping_j: 100.0,
            sliding_n_m: 50.0,
            sliding_above_yield_n_m: 5.0,
            lumped_archard_m3: 1e-12,
            local_archard_m3: 2e-12,
        };
        let inc = IncrementWork {
            contact_names: vec!["cube-tube".into()],
            contacts: vec![work],
            charge_mg_per_m3: vec![[("cube".to_string(), 2e9)].into_iter().collect()],
            hardness_pa: 1e9,
            yield_strength_pa: 4e8,
            point_pressures: true,
            drive_j: 150.0,
            energy_change_j: 0.0,
        };
        let measured: BTreeMap<_, _> = [(("C".to_string(), "cube".to_string()), 4.0)].into();
        let b = energy_budget(&[("C".into(), 8.0, vec![inc.clone(), inc])], &measured);
        let t = &b.tests[0];
        assert_eq!(t.contacts[0].damping_j, 200.0);
        assert_eq!(t.drive_j, 300.0);
        assert_eq!(t.contacts[0].damping_to_friction, 10.0);
        assert_eq!(t.contacts[0].share_above_yield, 0.1);
        let get = |name: &str| t.needed.iter().find(|n| n.mechanism == name).unwrap();
        // 4 mg = K * 100 N m * 2e9 mg/m³ -> K = 2e-11 m²/N, above the range's 7.6e-12.
        assert!((get("sliding_archard").value.unwrap() - 2e-11).abs() < 1e-24);
        assert_eq!(get("sliding_archard").verdict, "above");
        // 4 mg = k_E * 200 J * 2e9 -> 1e-11 m³/J, within.
        assert!((get("impact_wear").value.unwrap() - 1e-11).abs() < 1e-24);
        assert_eq!(get("impact_wear").verdict, "within");
        // severe: driver 10 N m / 1e9 Pa -> k = 4 / (1e-8 * 2e9) = 0.2, above.
        assert!((get("severe_wear").value.unwrap() - 0.2).abs() < 1e-12);
    }
}
