//! `impact-split`: where issue 28's error-control difference comes from. A case (rattle box C
//! by default) runs with full error control and with position-only error control without the
//! work test (the 5-7x faster mode of issue 16), and each run's time integral of `N·|v_slip|`
//! (the friction power users read), of friction power `μ N |v_slip|` and of damping power is
//! split, per contact track and accepted step, into the approach transient after each touch
//! and the rest. Three definitions of the approach transient are tabulated side by side:
//! - the steps that start within `--window-us` of the track's touch (the "first ~10 µs");
//! - the steps from the touch up to and including the first accepted state with `ẇ <= 0` (the
//!   approach until it is arrested, whatever it lasts);
//! - "fast normal motion": the touch's first step and every step with `|ẇ| > --fast-rate` at
//!   either end (an impact-like normal motion inside a persistent contact too: a cube slapping
//!   flat onto a wall it already touches with an edge stays one track).
//!
//! A track touches at the first accepted step where it is active after a step where it was
//! not; the touch time is taken as that step's start (the integrator does not locate it).
//! Each step's trapezoid of a track's power goes whole to the part its classification names.

use super::*;
use railwear::models::run::run_model_observed;
use railwear::physics::integrator::ErrorControl;
use std::collections::HashMap;

/// What `impact-split` runs.
pub(crate) struct ImpactSplitBench {
    pub(crate) cases: String,
    pub(crate) settle: f64,
    pub(crate) window: f64,
    /// Length of the approach window after a touch, s.
    pub(crate) approach_s: f64,
    /// |ẇ| above which a step is "fast normal motion", m/s.
    pub(crate) fast_rate_m_s: f64,
}

/// Power integrals, J: N·|v_slip| (N·m), friction, damping.
#[derive(Clone, Copy, Default)]
struct Works {
    normal_slip: f64,
    friction: f64,
    damping: f64,
}

impl Works {
    fn add(&mut self, dt: f64, a: &Powers, b: &Powers) {
        self.normal_slip += 0.5 * dt * (a.normal_slip + b.normal_slip);
        self.friction += 0.5 * dt * (a.friction + b.friction);
        self.damping += 0.5 * dt * (a.damping + b.damping);
    }
}

/// A track's powers and penetration rate at an accepted state.
#[derive(Clone, Copy, Default)]
struct Powers {
    normal_slip: f64,
    friction: f64,
    damping: f64,
    rate: f64,
}

/// A track between steps.
struct TrackMemory {
    touch_s: f64,
    arrested: bool,
    last: Option<Powers>,
}

/// One run's split: [within window, rest], [until arrest, rest], [fast, rest].
#[derive(Default)]
struct Split {
    window: [Works; 2],
    arrest: [Works; 2],
    fast: [Works; 2],
    touches: u64,
    accepted: u64,
    cpu_s: Option<f64>,
    mean_friction_power_w: f64,
}

fn run_split(
    configs_dir: &Path,
    case_name: &str,
    b: &ImpactSplitBench,
    mode: ErrorControl,
    work_test: bool,
    factor: f64,
) -> Result<Split> {
    let mut case = load_case(&configs_dir.join(format!("{case_name}.toml")))?;
    case.simulation.settle_s = b.settle;
    case.simulation.duration_s = b.window;
    case.simulation.rel_tolerance *= factor;
    case.simulation.abs_tolerance_m *= factor;
    case.simulation.error_control = mode;
    if !work_test {
        case.simulation.energy_rel_tolerance = Some(0.0);
    }
    let model = build(&case, configs_dir)?;
    let mut options = run_options(&case)?;
    options.record_interval_s = -1.0;
    let mut split = Split::default();
    let mut memory: HashMap<(u32, u32), TrackMemory> = HashMap::new();
    let mut seen_first = false;
    let cpu0 = thread_cpu_s();
    let report = run_model_observed(&model, &options, &RunControl::silent(), &mut |v| {
        let now: HashMap<(u32, u32), Powers> = v
            .tracks
            .iter()
            .map(|tr| {
                (
                    (tr.contact, tr.track),
                    Powers {
                        normal_slip: tr.normal_force * tr.slip_speed,
                        friction: tr.friction_power,
                        damping: tr.damping_power,
                        rate: tr.penetration_rate,
                    },
                )
            })
            .collect();
        // The first step seen opens the window: nothing to integrate yet.
        let dt = if seen_first { v.t - v.t_prev } else { 0.0 };
        seen_first = true;
        for key in now.keys() {
            let m = memory.entry(*key).or_insert(TrackMemory {
                touch_s: v.t_prev,
                arrested: false,
                last: None,
            });
            if m.last.is_none() {
                // A touch (or the track was active when the window opened).
                m.touch_s = v.t_prev;
                m.arrested = false;
                split.touches += 1;
            }
        }
        let zero = Powers::default();
        for (key, m) in memory.iter_mut() {
            let after = now.get(key);
            let before = m.last.as_ref();
            if after.is_none() && before.is_none() {
                continue;
            }
            let a = before.unwrap_or(&zero);
            let e = after.unwrap_or(&zero);
            let first_step = before.is_none();
            let in_window = usize::from(v.t_prev >= m.touch_s + b.approach_s);
            let in_approach = usize::from(m.arrested);
            let fast = first_step
                || a.rate.abs() > b.fast_rate_m_s
                || e.rate.abs() > b.fast_rate_m_s;
            split.window[in_window].add(dt, a, e);
            split.arrest[in_approach].add(dt, a, e);
            split.fast[usize::from(!fast)].add(dt, a, e);
            if e.rate <= 0.0 {
                m.arrested = true;
            }
            m.last = after.copied();
        }
    })
    .map_err(|e| anyhow!("{case_name} {}: {e}", mode.name()))?;
    split.cpu_s = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    split.accepted = report.integrator.accepted;
    split.mean_friction_power_w = report.mean_friction_power_w;
    Ok(split)
}

pub(crate) fn impact_split(configs_dir: &Path, b: &ImpactSplitBench) -> Result<Vec<Table>> {
    if !(b.window > 0.0 && b.approach_s > 0.0 && b.fast_rate_m_s > 0.0) {
        bail!("--window, --window-us and --fast-rate must be > 0");
    }
    let variants = [
        ("full, tol", ErrorControl::Full, true, 1.0),
        ("positions, no work test, tol", ErrorControl::Positions, false, 1.0),
        ("full, tol/4 (reference)", ErrorControl::Full, true, 0.25),
    ];
    let mut runs = Table::new(
        "Impact split: runs",
        &[
            ("case", "case"),
            ("variant", "variant"),
            ("accepted", "accepted"),
            ("cpu_s", "CPU s"),
            ("touches_per_s", "touches per s"),
            ("mean_friction_power_w", "mean N·|v_slip| W (report)"),
        ],
    );
    let mut parts = Table::new(
        "Impact split: time integrals over the window per part, and the fast mode's difference to full",
        &[
            ("case", "case"),
            ("split", "approach transient ="),
            ("quantity", "integral"),
            ("part", "part"),
            ("full", "full, tol"),
            ("positions", "positions, no work test"),
            ("reference", "full, tol/4"),
            ("diff", "positions − full"),
            ("share", "share of the total difference"),
        ],
    );
    for case_name in b.cases.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let mut measured = Vec::new();
        for (label, mode, work_test, factor) in variants {
            eprintln!("impact-split: {case_name} {label} ...");
            let s = run_split(configs_dir, case_name, b, mode, work_test, factor)?;
            runs.row(vec![
                Cell::text(case_name),
                Cell::text(label),
                Cell::Int(s.accepted),
                Cell::opt(s.cpu_s),
                Cell::Num(s.touches as f64 / b.window),
                Cell::Num(s.mean_friction_power_w),
            ]);
            measured.push(s);
        }
        let splits: [(&str, fn(&Split) -> &[Works; 2]); 3] = [
            ("steps starting within the window after touch", |s| &s.window),
            ("touch until arrest (first ẇ <= 0)", |s| &s.arrest),
            ("touch step or |ẇ| > fast rate", |s| &s.fast),
        ];
        let quantities: [(&str, fn(&Works) -> f64); 3] = [
            ("∫N·|v_slip| dt (N·m)", |w| w.normal_slip),
            ("friction work ∫μN|v_slip| dt (J)", |w| w.friction),
            ("damping work (J)", |w| w.damping),
        ];
        for (split_name, get) in splits {
            for (q_name, q) in quantities {
                let total = |s: &Split| q(&get(s)[0]) + q(&get(s)[1]);
                let total_diff = total(&measured[1]) - total(&measured[0]);
                for (pi, part) in ["approach", "rest", "total"].into_iter().enumerate() {
                    let value = |s: &Split| match pi {
                        2 => total(s),
                        i => q(&get(s)[i]),
                    };
                    let diff = value(&measured[1]) - value(&measured[0]);
                    parts.row(vec![
                        Cell::text(case_name),
                        Cell::text(split_name),
                        Cell::text(q_name),
                        Cell::text(part),
                        Cell::Num(value(&measured[0])),
                        Cell::Num(value(&measured[1])),
                        Cell::Num(value(&measured[2])),
                        Cell::Num(diff),
                        Cell::text(format!("{:.1} %", 100.0 * diff / total_diff)),
                    ]);
                }
            }
        }
    }
    let setup = format!(
        "settle {} s, window {} s (integrals over the window); approach window {} µs after a \
         track's touch; fast rate {} m/s; tolerance factors on the case's rel and abs \
         tolerances; no track recording",
        b.settle,
        b.window,
        b.approach_s * 1e6,
        b.fast_rate_m_s
    );
    runs.note(setup.clone());
    runs.note(machine_note());
    parts.note(setup);
    Ok(vec![runs, parts])
}
