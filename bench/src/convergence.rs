//! `convergence`: the error-control decision of issue 16. For each case (rattle box C, D,
//! launcher-design) the quantities users read (friction power, wear rate per contact, share of
//! the friction work above the wear law's cutoff, response PSD of the free body in 1/3-octave
//! bands up to 500 Hz) at the case tolerance and at half of it, for each error-control mode,
//! against a tight velocity-controlled reference (full error control at a fraction of the
//! tolerance), with relative differences; and the same mode again from an initial state moved
//! by 1 nm, the chaotic spread that no tolerance removes from a finite window.

use super::*;
use railwear::analysis::spectra::welch_psd;
use railwear::physics::contact::{FaceContact, FrictionRule};
use railwear::physics::integrator::ErrorControl;

/// One run of the convergence study.
#[derive(Clone)]
pub(crate) struct Variant {
    pub(crate) label: String,
    pub(crate) mode: ErrorControl,
    /// Tolerance factor applied to the case's `rel_tolerance` and `abs_tolerance_m` (and so to
    /// the energy tolerance, which follows `rel_tolerance`).
    pub(crate) factor: f64,
    /// Energy account's work test off (the account is still kept).
    pub(crate) energy_off: bool,
    /// Initial position moved by this much along x, m (chaos floor).
    pub(crate) nudge_m: f64,
    /// Contact points per box edge (None: the case's).
    pub(crate) points_per_edge: Option<usize>,
    /// Face resolution (None: the case's).
    pub(crate) face_contact: Option<FaceContact>,
    /// Where the exact face contact takes friction (a measurement; cases are per node).
    pub(crate) friction_rule: FrictionRule,
    /// The reduced face law's tolerance (None: the contacts' default).
    pub(crate) reduced_tolerance: Option<f64>,
}

impl Variant {
    /// Full error control at the case tolerance, from the case's initial state.
    pub(crate) fn plain(label: String) -> Self {
        Self {
            label,
            mode: ErrorControl::Full,
            factor: 1.0,
            energy_off: false,
            nudge_m: 0.0,
            points_per_edge: None,
            face_contact: None,
            friction_rule: FrictionRule::PerNode,
            reduced_tolerance: None,
        }
    }
}

/// What one run measured.
pub(crate) struct Measured {
    pub(crate) accepted: u64,
    rejected: u64,
    rhs: u64,
    wall_s: f64,
    pub(crate) cpu_s: Option<f64>,
    pub(crate) simulated_s: f64,
    pub(crate) energy_residual_rel: Option<f64>,
    /// (name, value, kind) of every user quantity.
    pub(crate) quantities: Vec<(String, f64, QuantityKind)>,
    /// The reduced face law's parts over the run, summed over its contacts (largest estimate
    /// the largest): None when no contact uses it.
    pub(crate) reduced: Option<railwear::physics::contact::ReducedShare>,
}

#[derive(Clone, Copy, PartialEq)]
pub(crate) enum QuantityKind {
    /// Compared by relative difference.
    Relative,
    /// A share in 0..1: compared by its absolute difference (percentage points).
    Share,
}

/// Centre frequencies of the base-10 1/3-octave bands from 20 to 500 Hz (IEC 61260 nominal).
const THIRD_OCTAVE_HZ: [f64; 15] = [
    20.0, 25.0, 31.5, 40.0, 50.0, 63.0, 80.0, 100.0, 125.0, 160.0, 200.0, 250.0, 315.0, 400.0,
    500.0,
];

/// This thread's CPU time, s (utime + stime of /proc/thread-self/stat at 100 ticks/s).
pub(crate) fn thread_cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start after the last ')'.
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // rest[0] is field 3 (state): utime is field 14, stime 15.
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

pub(crate) fn run_variant(
    configs_dir: &Path,
    case_name: &str,
    settle: f64,
    window: f64,
    v: &Variant,
) -> Result<Measured> {
    let mut case = load_case(&configs_dir.join(format!("{case_name}.toml")))?;
    case.simulation.settle_s = settle;
    case.simulation.duration_s = window;
    case.simulation.record_interval_s = case.simulation.record_interval_s.min(window);
    case.simulation.rel_tolerance *= v.factor;
    case.simulation.abs_tolerance_m *= v.factor;
    case.simulation.error_control = v.mode;
    if v.energy_off {
        case.simulation.energy_rel_tolerance = Some(0.0);
    }
    if let Some(n) = v.points_per_edge {
        case.simulation.contact_points_per_edge = n;
    }
    if let Some(f) = v.face_contact {
        case.simulation.face_contact = Some(f);
    }
    let mut model = build(&case, configs_dir)?;
    model.initial_state[0] += v.nudge_m;
    for c in &mut model.system.contacts {
        c.friction_rule = v.friction_rule;
        if let Some(tol) = v.reduced_tolerance {
            c.reduced_tolerance = tol;
        }
    }
    let mut options = run_options(&case)?;
    // Output is not engine work: no track samples (the wear integral sees every step anyway).
    options.record_interval_s = -1.0;
    let cpu0 = thread_cpu_s();
    let report = run_model(&model, &options, &RunControl::silent())
        .map_err(|e| anyhow!("{case_name} {}: {e}", v.label))?;
    let cpu = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    let mut quantities = vec![(
        "friction power Σ N·|v_slip| (W)".to_string(),
        report.mean_normal_slip_power_w,
        QuantityKind::Relative,
    )];
    for c in &report.contacts {
        quantities.push((
            format!("wear rate {} (mg/h)", c.name),
            c.mass_rate_mg_per_h,
            QuantityKind::Relative,
        ));
    }
    for c in &report.contacts {
        quantities.push((
            format!("work above cutoff {} (share)", c.name),
            c.work_share_above_cutoff,
            QuantityKind::Share,
        ));
    }
    let ax: Vec<f64> = report.response_acceleration.iter().map(|a| a[0]).collect();
    let segment = 2048.min(ax.len());
    if segment >= 4 {
        let psd = welch_psd(&ax, report.response_rate_hz, segment)
            .map_err(|e| anyhow!("response PSD: {e}"))?;
        let df = psd.resolution_hz();
        for fc in THIRD_OCTAVE_HZ {
            let (lo, hi) = (fc * 10f64.powf(-0.05), fc * 10f64.powf(0.05));
            let power: f64 = psd
                .frequency_hz
                .iter()
                .zip(&psd.density)
                .filter(|(f, _)| **f >= lo && **f < hi)
                .map(|(_, d)| d * df)
                .sum();
            quantities.push((
                format!("response x band {fc} Hz ((m/s²)²)"),
                power,
                QuantityKind::Relative,
            ));
        }
    }
    Ok(Measured {
        accepted: report.integrator.accepted,
        rejected: report.integrator.rejected,
        rhs: report.integrator.rhs_evals,
        wall_s: report.wall_s,
        cpu_s: cpu,
        simulated_s: settle + window,
        energy_residual_rel: report
            .energy
            .as_ref()
            .map(|e| e.residual_j.abs() / e.dissipated_j.max(1e-30)),
        quantities,
        reduced: reduced_share(&model),
    })
}

/// The reduced face law's census of `model`'s contacts that use it, summed.
fn reduced_share(model: &BuiltModel) -> Option<railwear::physics::contact::ReducedShare> {
    let mut any = None;
    for c in &model.system.contacts {
        if c.face_contact != FaceContact::Reduced {
            continue;
        }
        let s = c.reduced_census.snapshot();
        let sum = any.get_or_insert(railwear::physics::contact::ReducedShare::default());
        sum.closed_parts += s.closed_parts;
        sum.per_node_parts += s.per_node_parts;
        sum.over_tolerance_parts += s.over_tolerance_parts;
        sum.largest_estimate = sum.largest_estimate.max(s.largest_estimate);
    }
    any
}

/// `x` replaces the worst difference so far (a NaN always does: it is reported, not hidden).
fn worse(x: f64, worst: f64) -> bool {
    x.is_nan() || x > worst
}

fn difference(kind: QuantityKind, a: f64, b: f64) -> f64 {
    match kind {
        QuantityKind::Relative => {
            if a == b {
                0.0
            } else {
                (a - b) / b.abs().max(f64::MIN_POSITIVE)
            }
        }
        QuantityKind::Share => a - b,
    }
}

pub(crate) struct ConvergenceBench {
    /// Face study: lattice points per edge whose runs are extrapolated to the reference
    /// (empty: no face study).
    pub(crate) faces: Vec<usize>,
    /// Face study: also the exact contact with friction per part (`FrictionRule::PerPart`).
    pub(crate) friction_per_part: bool,
    pub(crate) cases: String,
    pub(crate) settle_box: f64,
    pub(crate) settle_launcher: f64,
    pub(crate) window: f64,
    pub(crate) reference_factor: f64,
    pub(crate) criterion: f64,
    pub(crate) with_energy_off: bool,
    /// Ladder: contact points per box edge of the runs (None: the case's).
    pub(crate) points_per_edge: Option<usize>,
    /// Ladder: contact points per box edge of the reference (None: the case's).
    pub(crate) reference_points_per_edge: Option<usize>,
}

impl ConvergenceBench {
    /// The case names of `--cases`.
    pub(crate) fn case_names(&self) -> impl Iterator<Item = &str> {
        self.cases
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
    }

    /// Settle time of a case: the launcher's or the rattle box's.
    pub(crate) fn settle(&self, case_name: &str) -> f64 {
        if case_name.starts_with("launcher") {
            self.settle_launcher
        } else {
            self.settle_box
        }
    }
}

/// The case's own relative tolerance (the factors of the studies multiply it).
fn case_rel_tolerance(configs_dir: &Path, case_name: &str) -> Result<f64> {
    Ok(load_case(&configs_dir.join(format!("{case_name}.toml")))?
        .simulation
        .rel_tolerance)
}

/// An error-control mode of the study: its name, the mode and whether the energy account's
/// work test is on.
struct Mode {
    name: &'static str,
    control: ErrorControl,
    energy_off: bool,
}

const MODES: [Mode; 3] = [
    Mode {
        name: "full",
        control: ErrorControl::Full,
        energy_off: false,
    },
    Mode {
        name: "positions",
        control: ErrorControl::Positions,
        energy_off: false,
    },
    Mode {
        name: "positions, no work test",
        control: ErrorControl::Positions,
        energy_off: true,
    },
];

pub(crate) fn convergence(configs_dir: &Path, b: &ConvergenceBench) -> Result<Vec<Table>> {
    if !(b.window > 0.0 && b.reference_factor > 0.0 && b.reference_factor < 1.0) {
        bail!("--window must be > 0 and --reference-factor in (0, 1)");
    }
    let modes: Vec<&Mode> = MODES
        .iter()
        .filter(|m| b.with_energy_off || !m.energy_off)
        .collect();
    // Variant 0: the reference; 1: the nudge; then each mode at tol and tol/2.
    let mut variants = vec![
        Variant {
            label: "reference: full, tol × f".into(),
            mode: ErrorControl::Full,
            factor: b.reference_factor,
            energy_off: false,
            nudge_m: 0.0,
            points_per_edge: None,
            face_contact: None,
            friction_rule: FrictionRule::PerNode,
            reduced_tolerance: None,
        },
        Variant {
            label: "full, tol, start moved 1 nm".into(),
            mode: ErrorControl::Full,
            factor: 1.0,
            energy_off: false,
            nudge_m: 1e-9,
            points_per_edge: None,
            face_contact: None,
            friction_rule: FrictionRule::PerNode,
            reduced_tolerance: None,
        },
    ];
    for m in &modes {
        for (factor, tag) in [(1.0, "tol"), (0.5, "tol/2")] {
            variants.push(Variant {
                label: format!("{}, {tag}", m.name),
                mode: m.control,
                factor,
                energy_off: m.energy_off,
                nudge_m: 0.0,
                points_per_edge: None,
                face_contact: None,
                friction_rule: FrictionRule::PerNode,
                reduced_tolerance: None,
            });
        }
    }
    let at = |mode: usize, half: bool| 2 + 2 * mode + usize::from(half);
    let mut runs_table = Table::new(
        "Convergence study: runs (no track recording)",
        &[
            ("case", "case"),
            ("variant", "variant"),
            ("tolerance", "rel tolerance"),
            ("accepted", "accepted"),
            ("rejected", "rejected"),
            ("rhs", "right-hand sides"),
            ("cpu_s", "CPU s"),
            ("wall_s", "wall s"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("steps_vs_full", "accepted / full at tol"),
            ("energy_residual", "energy residual / dissipated"),
        ],
    );
    // Quantity table: the reference value, then each mode's Δ at tol and tol/2 against the
    // reference and its halving Δ, then the nudge.
    const MODE_COLUMNS: [[(&str, &str); 3]; 3] = [
        [
            ("full_ref", "Δ full tol vs ref"),
            ("full_half_ref", "Δ full tol/2 vs ref"),
            ("full_half", "Δ full tol/2 vs tol"),
        ],
        [
            ("pos_ref", "Δ positions tol vs ref"),
            ("pos_half_ref", "Δ positions tol/2 vs ref"),
            ("pos_half", "Δ positions tol/2 vs tol"),
        ],
        [
            ("posnw_ref", "Δ positions (no work test) tol vs ref"),
            ("posnw_half_ref", "Δ positions (no work test) tol/2 vs ref"),
            ("posnw_half", "Δ positions (no work test) tol/2 vs tol"),
        ],
    ];
    let mut columns = vec![
        ("case", "case"),
        ("quantity", "quantity"),
        ("reference", "reference"),
    ];
    for cols in MODE_COLUMNS.iter().take(modes.len()) {
        columns.extend_from_slice(cols);
    }
    columns.push(("chaos", "Δ full tol, 1 nm nudge"));
    let mut quantity_table = Table::new(
        "Convergence study: user quantities, differences against the reference and on halving",
        &columns,
    );
    let mut verdict = Table::new(
        format!(
            "Convergence study: verdict (criterion |Δ| < {} % on every quantity, halving and against the reference)",
            b.criterion * 100.0
        ),
        &[
            ("case", "case"),
            ("mode", "mode"),
            ("worst_half", "worst |Δ| tol/2 vs tol"),
            ("worst_half_q", "at"),
            ("worst_ref", "worst |Δ| tol vs reference"),
            ("worst_ref_q", "at"),
            ("chaos", "worst |Δ| of the 1 nm nudge (chaos floor)"),
            ("steps", "accepted steps / full at tol"),
            ("pass", "passes"),
        ],
    );
    for case_name in b.case_names() {
        let settle = b.settle(case_name);
        let mut measured = Vec::new();
        for v in &variants {
            eprintln!("convergence: {case_name} {} ...", v.label);
            measured.push(run_variant(configs_dir, case_name, settle, b.window, v)?);
        }
        let full_steps = measured[at(0, false)].accepted as f64;
        let case_tol = case_rel_tolerance(configs_dir, case_name)?;
        for (v, m) in variants.iter().zip(&measured) {
            runs_table.row(vec![
                Cell::text(case_name),
                Cell::text(&v.label),
                Cell::Num(case_tol * v.factor),
                Cell::Int(m.accepted),
                Cell::Int(m.rejected),
                Cell::Int(m.rhs),
                Cell::opt(m.cpu_s),
                Cell::Num(m.wall_s),
                Cell::opt(m.cpu_s.map(|c| m.simulated_s / c.max(1e-9))),
                Cell::Num(m.accepted as f64 / full_steps),
                Cell::opt(m.energy_residual_rel),
            ]);
        }
        let reference = &measured[0];
        let chaos = &measured[1];
        // Worst differences per mode: (halving, vs reference).
        let mut worst: Vec<[(f64, String); 2]> = vec![Default::default(); modes.len()];
        let mut worst_chaos = 0.0f64;
        for (i, (name, r, kind)) in reference.quantities.iter().enumerate() {
            let val = |m: &Measured| m.quantities.get(i).map(|q| q.1).unwrap_or(f64::NAN);
            let d = |a: f64, b: f64| difference(*kind, a, b);
            let show = |x: f64| match kind {
                QuantityKind::Relative => Cell::text(format!("{:+.2} %", 100.0 * x)),
                QuantityKind::Share => Cell::text(format!("{:+.2} pp", 100.0 * x)),
            };
            let mut row = vec![Cell::text(case_name), Cell::text(name), Cell::Num(*r)];
            for (mi, w) in worst.iter_mut().enumerate() {
                let (tol, half) = (val(&measured[at(mi, false)]), val(&measured[at(mi, true)]));
                let (vs_ref, half_ref, halving) = (d(tol, *r), d(half, *r), d(half, tol));
                row.extend([show(vs_ref), show(half_ref), show(halving)]);
                for (k, x) in [halving, vs_ref].into_iter().enumerate() {
                    if worse(x.abs(), w[k].0) {
                        w[k] = (x.abs(), name.clone());
                    }
                }
            }
            let nudge = d(val(chaos), val(&measured[at(0, false)]));
            row.push(show(nudge));
            quantity_table.row(row);
            if worse(nudge.abs(), worst_chaos) {
                worst_chaos = nudge.abs();
            }
        }
        for (mi, m) in modes.iter().enumerate() {
            let [(h, hq), (r, rq)] = &worst[mi];
            verdict.row(vec![
                Cell::text(case_name),
                Cell::text(m.name),
                Cell::text(format!("{:.2} %", 100.0 * h)),
                Cell::text(hq),
                Cell::text(format!("{:.2} %", 100.0 * r)),
                Cell::text(rq),
                Cell::text(format!("{:.2} %", 100.0 * worst_chaos)),
                Cell::Num(measured[at(mi, false)].accepted as f64 / full_steps),
                Cell::text(if *h < b.criterion && *r < b.criterion {
                    "yes"
                } else {
                    "no"
                }),
            ]);
        }
    }
    let setup = format!(
        "settle {} s (rattle box) / {} s (launcher), window {} s; reference = full error control at {} × the case's \
         rel and abs tolerances (the work tolerance follows rel); response = x acceleration of the free body \
         (cube, missile) at 2 kHz, Welch PSD with 2048-sample Hann segments, power per base-10 1/3-octave band \
         (edges fc·10^(±1/20)); \"no work test\" = energy_rel_tolerance 0 (the account is still kept)",
        b.settle_box, b.settle_launcher, b.window, b.reference_factor
    );
    runs_table.note(setup.clone());
    runs_table.note(
        "CPU s = this thread's user + system time of the run (10 ms ticks); the machine is shared, \
         so compare ratios within one run",
    );
    runs_table.note(machine_note());
    quantity_table.note(setup);
    quantity_table.note(
        "Δ relative for forces, powers, rates and band powers; shares compare in percentage points (pp)",
    );
    verdict.note(
        "the 1 nm nudge is the full mode at the same tolerance from an initial state moved by 1e-9 m: \
         the chaotic spread of a finite window, which bounds how well any two runs can agree",
    );
    Ok(vec![runs_table, quantity_table, verdict])
}

/// The tolerance ladder: how loose the case tolerance may be made, with full error control and
/// the work test, before the quantities users read move by more than the criterion, on halving
/// or against the tight reference.
pub(crate) fn ladder(
    configs_dir: &Path,
    b: &ConvergenceBench,
    factors: &[f64],
) -> Result<Vec<Table>> {
    if factors.is_empty() || factors.iter().any(|f| !(f.is_finite() && *f > 0.0)) {
        bail!("--ladder must list tolerance factors > 0, e.g. 1,4,16,64");
    }
    let mut table = Table::new(
        format!(
            "Tolerance ladder: full error control with the work test, each factor f on the case tolerance \
             against f/2 and the reference (criterion |Δ| < {} %)",
            b.criterion * 100.0
        ),
        &[
            ("case", "case"),
            ("factor", "tolerance factor f"),
            ("tolerance", "rel tolerance"),
            ("accepted", "accepted"),
            ("rejected", "rejected"),
            ("cpu_s", "CPU s"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("speedup", "CPU speed-up over f = 1"),
            ("energy_residual", "energy residual / dissipated"),
            ("worst_half", "worst |Δ| f/2 vs f"),
            ("worst_half_q", "at"),
            ("worst_ref", "worst |Δ| f vs reference"),
            ("worst_ref_q", "at"),
            ("pass", "passes"),
        ],
    );
    let mut quantities = Table::new(
        "Tolerance ladder: every quantity against the reference and on halving",
        &[
            ("case", "case"),
            ("quantity", "quantity"),
            ("reference", "reference"),
            ("factor", "f"),
            ("value", "at f"),
            ("vs_ref", "Δ f vs reference"),
            ("halving", "Δ f/2 vs f"),
        ],
    );
    let full = |factor: f64, label: String, points_per_edge| Variant {
        label,
        mode: ErrorControl::Full,
        factor,
        energy_off: false,
        nudge_m: 0.0,
        points_per_edge,
        face_contact: None,
        friction_rule: FrictionRule::PerNode,
        reduced_tolerance: None,
    };
    let points = b.points_per_edge;
    for case_name in b.case_names() {
        let settle = b.settle(case_name);
        let case_tol = case_rel_tolerance(configs_dir, case_name)?;
        eprintln!("ladder: {case_name} reference ...");
        let reference = run_variant(
            configs_dir,
            case_name,
            settle,
            b.window,
            &full(
                b.reference_factor,
                "reference".into(),
                b.reference_points_per_edge,
            ),
        )?;
        let mut base_cpu = None;
        let mut loosest = None;
        for &f in factors {
            eprintln!("ladder: {case_name} f = {f} and f/2 ...");
            let at_f = run_variant(
                configs_dir,
                case_name,
                settle,
                b.window,
                &full(f, "f".into(), points),
            )?;
            let half = run_variant(
                configs_dir,
                case_name,
                settle,
                b.window,
                &full(0.5 * f, "f/2".into(), points),
            )?;
            let mut worst: [(f64, String); 2] = Default::default();
            for (i, (name, r, kind)) in reference.quantities.iter().enumerate() {
                let val = |m: &Measured| m.quantities.get(i).map(|q| q.1).unwrap_or(f64::NAN);
                let halving = difference(*kind, val(&half), val(&at_f)).abs();
                let vs_ref = difference(*kind, val(&at_f), *r).abs();
                let show = |x: f64| match kind {
                    QuantityKind::Relative => Cell::text(format!("{:.2} %", 100.0 * x)),
                    QuantityKind::Share => Cell::text(format!("{:.2} pp", 100.0 * x)),
                };
                quantities.row(vec![
                    Cell::text(case_name),
                    Cell::text(name),
                    Cell::Num(*r),
                    Cell::Num(f),
                    Cell::Num(val(&at_f)),
                    show(vs_ref),
                    show(halving),
                ]);
                for (k, x) in [halving, vs_ref].into_iter().enumerate() {
                    if worse(x, worst[k].0) {
                        worst[k] = (x, name.clone());
                    }
                }
            }
            let passes = worst[0].0 < b.criterion && worst[1].0 < b.criterion;
            if f == 1.0 {
                base_cpu = at_f.cpu_s;
            }
            if passes {
                loosest = Some((f, at_f.cpu_s));
            }
            table.row(vec![
                Cell::text(case_name),
                Cell::Num(f),
                Cell::Num(case_tol * f),
                Cell::Int(at_f.accepted),
                Cell::Int(at_f.rejected),
                Cell::opt(at_f.cpu_s),
                Cell::opt(at_f.cpu_s.map(|c| at_f.simulated_s / c.max(1e-9))),
                Cell::opt(base_cpu.zip(at_f.cpu_s).map(|(a, c)| a / c.max(1e-9))),
                Cell::opt(at_f.energy_residual_rel),
                Cell::text(format!("{:.2} %", 100.0 * worst[0].0)),
                Cell::text(&worst[0].1),
                Cell::text(format!("{:.2} %", 100.0 * worst[1].0)),
                Cell::text(&worst[1].1),
                Cell::text(if passes { "yes" } else { "no" }),
            ]);
        }
        table.note(match loosest {
            Some((f, cpu)) => format!(
                "{case_name}: loosest passing factor {f} (rel tolerance {:.1e}), CPU speed-up over f = 1: {}",
                case_tol * f,
                base_cpu
                    .zip(cpu)
                    .map_or("-".into(), |(a, c)| format!("{:.2}x", a / c.max(1e-9)))
            ),
            None => format!("{case_name}: no factor of the ladder passes"),
        });
    }
    let pts = |p: Option<usize>| p.map_or("the case's".to_string(), |n| n.to_string());
    table.note(format!(
        "settle {} s (rattle box) / {} s (launcher), window {} s, no track recording; reference = full \
         error control at {} × the case tolerance; the work tolerance follows rel (10 × rel); \
         quantities as in the convergence study; contact points per box edge: {} in the runs, {} in \
         the reference",
        b.settle_box,
        b.settle_launcher,
        b.window,
        b.reference_factor,
        pts(b.points_per_edge),
        pts(b.reference_points_per_edge)
    ));
    table.note(machine_note());
    Ok(vec![table, quantities])
}
