//! The next test (docs/results/diagnosis.md, "The next test"): for a report that is not
//! `explained` (or whose leading candidates are indistinguishable), the tests that would best
//! separate the leading candidate from its rivals, cheapest decisive first.
//!
//! 1. **Who** (`leaders`): the candidate the verdict leans on, at its fitted values, and up
//!    to [`leaders::MAX_RIVALS`] rivals besides the nominal model.
//! 2. **What could be run** (`setups`): the campaign's cases and the reference configs of its
//!    model, each under its own drive, a louder one and the two other axes (at most
//!    [`setups::MAX_SETUPS`] setups), read under a few schedules (increments, repeats,
//!    accelerometer records).
//! 3. **What each candidate predicts**: every setup simulated with each candidate through the
//!    rig's own segment path (the same windows as the diagnosis' emulator).
//! 4. **How well it separates** ([`separation`]): the expected log-likelihood ratio between
//!    the leading candidate and each rival under the campaign's noise model; a test is
//!    *decisive* when it exceeds [`DECISIVE_NATS`] against every rival.
//! 5. **Ranking**: held out by test, a test is predicted only from what the other tests
//!    inform, so an effect that one test carries (`Report::carried_by`, or a test of
//!    `Report::to_repeat`, which the leading candidate cannot predict held out) is confirmed
//!    only once a second test carries it. First the repeats of the `to_repeat` tests, each
//!    as it was run; then **a second carrying test**: the best setup of another case or drive
//!    that carries the leading candidate (decisive against the nominal model, `carries`)
//!    under its best such schedule; then the best schedule of each setup (decisive and
//!    cheapest, else the most separating), the setups in the same order; the first
//!    [`MAX_PROPOSED`] are proposed. (Led by the second carrying test, the bench lost a
//!    fixture compliance a repeat of A confirms: a test of D that is decisive against the
//!    nominal model carries a ten-thousandth of what A does.)

pub mod leaders;
pub mod separation;
pub mod setups;

use super::emulator::slots::{plan, predictions_of, simulate_slots, Slot};
use super::options::Simulating;
use super::prediction::Prediction;
use super::report::{CandidateReading, ProposedTest, Report, RivalSeparation};
use crate::gap::campaign::Campaign;
use crate::gap::GapError;
use leaders::{leaders, Leader};
use separation::{expected_log_lr, Readings, TestNoise};
use setups::{repeat_of, same_case, schedules, setups, test_entry, Schedule, Setup};

/// Expected log-likelihood ratio a test must give the true candidate over each rival to be
/// decisive: ln 20 (odds of 20 to 1, a 5 % error), in nats.
pub const DECISIVE_NATS: f64 = 2.995_732_273_553_991;

/// Tests proposed: the best of as many setups.
pub const MAX_PROPOSED: usize = 5;

/// Sensor noise assumed for proposed records when the campaign has none to take it from, RMS
/// m/s² (the bench rig's).
pub const ASSUMED_SENSOR_NOISE_M_S2: f64 = 0.5;

/// The next tests for `report` on `campaign` (module documentation); empty when the report
/// wants none. Simulates every setup with each candidate; a setup the simulator or an effect
/// refuses is left out (logged), a cancellation stops it.
pub fn propose(
    campaign: &Campaign,
    report: &Report,
    sim: Simulating,
) -> Result<Vec<ProposedTest>, GapError> {
    let Some((focal, rivals)) = leaders(report)? else {
        return Ok(Vec::new());
    };
    let (_, options, configs_dir, control, cache) = sim.parts();
    let candidates: Vec<&Leader> = std::iter::once(&focal).chain(&rivals).collect();
    let slots: Vec<Slot> = candidates
        .iter()
        .map(|c| (c.effects.clone(), 1.0, 0.0, 0.0))
        .collect();
    let schedules = schedules(campaign);
    let most = schedules.iter().map(|s| s.increments).max().unwrap_or(1);
    let components = components(campaign);
    let noise = test_noise(campaign, report, options);
    let simulate = |setup: &Setup| -> Result<Option<Vec<Vec<Prediction>>>, GapError> {
        let skeleton = Schedule {
            increments: most,
            repeats: 1,
            ..schedules[0]
        };
        let one = Campaign {
            tests: vec![test_entry(
                setup,
                &skeleton,
                "next",
                &components,
                noise.resolution_mg,
                String::new(),
            )],
            ..campaign.clone()
        };
        let simulated = plan(&one, configs_dir).and_then(|planned| {
            simulate_slots(
                &slots,
                &one,
                (&planned.0, &planned.1),
                configs_dir,
                &options.emulator,
                control,
                cache,
                &|_, _| {},
                (0, slots.len()),
            )
        });
        match simulated {
            Ok(by_slot) => Ok(Some(
                by_slot
                    .iter()
                    .map(|s| predictions_of(s).into_iter().next().unwrap_or_default())
                    .collect(),
            )),
            Err(e) if control.is_cancelled() => Err(e),
            Err(e) => {
                tracing::warn!(setup = %setup.change, error = %e, "next test: setup left out");
                Ok(None)
            }
        }
    };
    // Repeats first: where held-out data cannot confirm the leading candidate, the tests that
    // would let them.
    let mut repeats: Vec<Ranked> = Vec::new();
    for id in &report.to_repeat {
        let Some((setup, schedule)) = repeat_of(campaign, id, configs_dir) else {
            continue;
        };
        if let Some(by_candidate) = simulate(&setup)? {
            let mut r = rank(
                &setup,
                &schedule,
                &by_candidate,
                &candidates,
                &components,
                &noise,
            );
            r.repeats_test = Some(id.clone());
            repeats.push(r);
        }
    }
    // The tests that alone carry the leading candidate: a second test of another case or
    // drive that carries it lets each be predicted held out from the other.
    let carrying: Vec<&crate::gap::campaign::CampaignTest> = report
        .carried_by
        .iter()
        .chain(&report.to_repeat)
        .filter_map(|id| campaign.tests.iter().find(|t| &t.id == id))
        .collect();
    let mut second: Vec<Ranked> = Vec::new();
    let mut best: Vec<Ranked> = Vec::new();
    for setup in setups(campaign, configs_dir) {
        let Some(by_candidate) = simulate(&setup)? else {
            continue;
        };
        let ranked: Vec<Ranked> = schedules
            .iter()
            .map(|s| rank(&setup, s, &by_candidate, &candidates, &components, &noise))
            .collect();
        if let Some(first) = carrying.first() {
            if !carrying.iter().any(|t| same_case(&setup, t)) {
                let carried = ranked
                    .iter()
                    .filter(|r| carries(r))
                    .min_by(|a, b| Ranked::order(a, b));
                if let Some(r) = carried {
                    second.push(Ranked {
                        second_to: Some(first.id.clone()),
                        ..r.clone()
                    });
                }
            }
        }
        best.extend(ranked.into_iter().min_by(Ranked::order));
    }
    best.sort_by(Ranked::order);
    // The repeats, then the best second carrying test; the other setups keep their place.
    let second: Option<Ranked> = second.into_iter().min_by(Ranked::order);
    let lead = second.as_ref().map(|s| s.setup.clone());
    let mut ordered: Vec<Ranked> = repeats;
    ordered.extend(second);
    ordered.extend(best.into_iter().filter(|b| lead.as_ref() != Some(&b.setup)));
    let ids = fresh_ids(campaign, ordered.len().min(MAX_PROPOSED));
    Ok(ordered
        .into_iter()
        .zip(ids)
        .map(|(r, id)| r.proposed(&id, &components, &noise))
        .collect())
}

/// Whether a ranked test carries the leading candidate: decisive against the nominal model
/// (the first rival, [`leaders`]), so the test alone would show the effect.
fn carries(r: &Ranked) -> bool {
    r.separations.first().is_some_and(|&x| x > DECISIVE_NATS)
}

/// One setup under one schedule with its separations.
#[derive(Clone)]
struct Ranked {
    setup: Setup,
    schedule: Schedule,
    names: Vec<String>,
    /// Per candidate, per increment (the schedule's).
    predictions: Vec<Vec<Prediction>>,
    /// Per rival.
    separations: Vec<f64>,
    /// The campaign test it repeats (`Report::to_repeat`).
    repeats_test: Option<String>,
    /// The campaign test that alone carries the leading candidate, which this test of
    /// another case or drive carries too.
    second_to: Option<String>,
}

impl Ranked {
    fn separation(&self) -> f64 {
        self.separations
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }

    fn decisive(&self) -> bool {
        self.separation() > DECISIVE_NATS
    }

    /// Decisive first, the cheapest of them first (the more separating of equal cost); then
    /// the most separating.
    fn order(a: &Self, b: &Self) -> std::cmp::Ordering {
        b.decisive().cmp(&a.decisive()).then_with(|| {
            if a.decisive() {
                a.schedule
                    .cost_h()
                    .total_cmp(&b.schedule.cost_h())
                    .then(b.separation().total_cmp(&a.separation()))
            } else {
                b.separation()
                    .total_cmp(&a.separation())
                    .then(a.schedule.cost_h().total_cmp(&b.schedule.cost_h()))
            }
        })
    }

    fn proposed(self, id: &str, components: &[String], noise: &TestNoise) -> ProposedTest {
        let separation = self.separation();
        let decisive = self.decisive();
        let s = self.schedule;
        let description = match (&self.repeats_test, &self.second_to) {
            (_, Some(id)) => format!(
                "Proposed by the diagnosis so that a second test carries {}: test {id} alone carries it, and held out one carrying test is not predicted from the others ({}; expected log-likelihood ratio {:.1} nats against the nominal model, {separation:.1} against {})",
                self.names[0],
                self.setup.change,
                self.separations.first().copied().unwrap_or(0.0),
                self.names[1..].join(", ")
            ),
            (Some(id), None) => format!(
                "Proposed by the diagnosis to confirm {} where held-out data cannot: test {id} repeated ({}; expected log-likelihood ratio {separation:.1} nats against {})",
                self.names[0],
                self.setup.change,
                self.names[1..].join(", ")
            ),
            (None, None) => format!(
                "Proposed by the diagnosis to tell {} from {} ({}; expected log-likelihood ratio {separation:.1} nats)",
                self.names[0],
                self.names[1..].join(", "),
                self.setup.change
            ),
        };
        let test = test_entry(
            &self.setup,
            &s,
            id,
            components,
            noise.resolution_mg,
            description,
        );
        let component = components.first().cloned().unwrap_or_default();
        let predictions: Vec<CandidateReading> = self
            .names
            .iter()
            .zip(&self.predictions)
            .map(|(name, p)| reading(name, p, &component, &s, noise))
            .collect();
        let rivals: Vec<RivalSeparation> = self.names[1..]
            .iter()
            .zip(&self.separations)
            .map(|(name, &x)| RivalSeparation {
                candidate: name.clone(),
                expected_log_lr: x,
                decisive: x > DECISIVE_NATS,
            })
            .collect();
        let decides = rivals
            .iter()
            .zip(&predictions[1..])
            .map(|(r, p)| decides(&predictions[0], p, r))
            .collect();
        ProposedTest {
            test,
            case: self.setup.case.clone(),
            change: self.setup.change.clone(),
            repeats_test: self.repeats_test,
            second_to: self.second_to,
            drive_axis: self.setup.drive_axis.clone(),
            level_g: self.setup.level_g,
            frequency_hz: self.setup.frequency_hz,
            increments: s.increments,
            increment_duration_s: s.increment_duration_s,
            repeats: s.repeats,
            accelerometers: s.accelerometers,
            cost_h: s.cost_h(),
            separates: self.names,
            separation_nats: separation,
            decisive,
            rivals,
            predictions,
            decides,
        }
    }
}

fn rank(
    setup: &Setup,
    schedule: &Schedule,
    by_candidate: &[Vec<Prediction>],
    candidates: &[&Leader],
    components: &[String],
    noise: &TestNoise,
) -> Ranked {
    let predictions: Vec<Vec<Prediction>> = by_candidate
        .iter()
        .map(|p| p.iter().take(schedule.increments).cloned().collect())
        .collect();
    let readings = Readings {
        increments: schedule.increments,
        components,
        repeats: schedule.repeats,
        accelerometers: schedule.accelerometers,
    };
    let separations = predictions[1..]
        .iter()
        .map(|rival| expected_log_lr(&predictions[0], rival, readings, noise))
        .collect();
    Ranked {
        setup: setup.clone(),
        schedule: *schedule,
        names: candidates.iter().map(|c| c.name.clone()).collect(),
        predictions,
        separations,
        repeats_test: None,
        second_to: None,
    }
}

/// A candidate's predicted mass of `component` per increment, with its 95 % interval.
fn reading(
    name: &str,
    p: &[Prediction],
    component: &str,
    s: &Schedule,
    noise: &TestNoise,
) -> CandidateReading {
    let n = s.repeats.max(1) as f64;
    let mass_mg: Vec<f64> = p
        .iter()
        .map(|x| x.mass_mg.get(component).copied().unwrap_or(0.0))
        .collect();
    let interval_mg = mass_mg
        .iter()
        .map(|&mu| {
            let u = ((noise.mass_rel.powi(2) / n + noise.mass_model_rel_var) * mu * mu
                + noise.resolution_mg.powi(2) / 12.0 / n)
                .sqrt();
            [(mu - 1.96 * u).max(0.0), mu + 1.96 * u]
        })
        .collect();
    CandidateReading {
        candidate: name.to_string(),
        quantity: format!("mass {component}"),
        mass_mg,
        interval_mg,
    }
}

/// What the outcome decides between the leading candidate `a` and rival `b`, in words.
fn decides(a: &CandidateReading, b: &CandidateReading, r: &RivalSeparation) -> String {
    let at = |c: &CandidateReading| match (c.mass_mg.first(), c.interval_mg.first()) {
        (Some(m), Some([lo, hi])) => format!("{m:.3e} mg [{lo:.3e}, {hi:.3e}]"),
        _ => "nothing".to_string(),
    };
    let strength = if r.decisive {
        "decisive"
    } else {
        "not decisive"
    };
    format!(
        "{} of the first increment near {} favours {}; near {} favours {} (expected log-likelihood ratio {:.1} nats, {strength})",
        a.quantity,
        at(a),
        a.candidate,
        at(b),
        b.candidate,
        r.expected_log_lr
    )
}

/// Every weighed component of the campaign, in order of first appearance.
fn components(campaign: &Campaign) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for c in campaign.tests.iter().flat_map(|t| &t.components) {
        if !out.contains(c) {
            out.push(c.clone());
        }
    }
    out
}

/// The noise of a proposed test's readings from the report's noise model and the campaign's
/// finest scale and noisiest sensor.
fn test_noise(
    campaign: &Campaign,
    report: &Report,
    options: &super::options::DiagnoseOptions,
) -> TestNoise {
    let n = &report.noise;
    let resolution_mg = campaign
        .tests
        .iter()
        .map(|t| t.scale_resolution_mg)
        .fold(f64::INFINITY, f64::min);
    let sensor = campaign
        .tests
        .iter()
        .flat_map(|t| &t.specimens)
        .flat_map(|s| &s.accelerometers)
        .map(|r| r.sensor_noise_m_s2)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
    let labels = [
        "input x",
        "input y",
        "input z",
        "response x",
        "response y",
        "response z",
    ];
    let mut accel_model_rel_var = [0.0; 6];
    for (v, label) in accel_model_rel_var.iter_mut().zip(labels) {
        *v = n
            .numerical_accel_rel
            .get(label)
            .copied()
            .unwrap_or(0.0)
            .powi(2);
    }
    TestNoise {
        mass_rel: n.mass_repeatability_rel,
        mass_model_rel_var: n.numerical_mass_rel.powi(2)
            + n.k_rel_uncertainty.powi(2)
            + n.friction_mass_rel.powi(2),
        resolution_mg: if resolution_mg.is_finite() {
            resolution_mg
        } else {
            crate::gap::campaign::MIN_SCALE_RESOLUTION_MG
        },
        accel_rel: n.accel_repeatability_rel,
        accel_model_rel_var,
        calibration_var: (2.0 * n.accelerometer_calibration_rel).powi(2),
        sensor_noise_m_s2: sensor.unwrap_or(ASSUMED_SENSOR_NOISE_M_S2),
        samples: (options.emulator.accelerometer_rate_hz * options.emulator.window_s)
            .round()
            .max(1.0) as usize,
    }
}

/// `next-1`, `next-2`, ... not used by a test of the campaign.
fn fresh_ids(campaign: &Campaign, n: usize) -> Vec<String> {
    (1..)
        .map(|k| format!("next-{k}"))
        .filter(|id| campaign.tests.iter().all(|t| &t.id != id))
        .take(n)
        .collect()
}
