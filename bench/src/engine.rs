//! `engine`: integrators on rattle box C and a Hertz sphere bounce.

use super::*;

pub(crate) struct SphereRun {
    pub(crate) simulated_s: f64,
    pub(crate) wall_s: f64,
    pub(crate) accepted: u64,
    pub(crate) rejected: u64,
    pub(crate) mean_normal_force_n: f64,
    pub(crate) mean_normal_slip_power_w: f64,
    pub(crate) vdv_y: Option<f64>,
}

/// Time-weighted (trapezoid) means of N and N·|v_slip| and a uniformly resampled velocity, from
/// the accepted steps a simulation reports.
pub(crate) struct StepMeans {
    pub(crate) t_from: f64,
    pub(crate) prev: Option<(f64, f64, f64)>,
    pub(crate) normal_int: f64,
    pub(crate) power_int: f64,
    pub(crate) dt_resp: f64,
    pub(crate) next_resp: f64,
    pub(crate) prev_vel: Option<(f64, f64)>,
    pub(crate) vel: Vec<f64>,
}

impl StepMeans {
    pub(crate) fn new(t_from: f64, rate_hz: f64) -> Self {
        Self {
            t_from,
            prev: None,
            normal_int: 0.0,
            power_int: 0.0,
            dt_resp: 1.0 / rate_hz,
            next_resp: t_from,
            prev_vel: None,
            vel: Vec::new(),
        }
    }
    pub(crate) fn push(&mut self, v: &StepView, velocity: f64) {
        if v.t < self.t_from {
            return;
        }
        let n: f64 = v.tracks.iter().map(|t| t.normal_force).sum();
        let p: f64 = v.tracks.iter().map(|t| t.normal_force * t.slip_speed).sum();
        if let Some((tp, np, pp)) = self.prev {
            let dt = v.t - tp;
            self.normal_int += 0.5 * dt * (np + n);
            self.power_int += 0.5 * dt * (pp + p);
        }
        self.prev = Some((v.t, n, p));
        if let Some((tp, vp)) = self.prev_vel {
            while self.next_resp <= v.t && v.t > tp {
                let s = ((self.next_resp - tp) / (v.t - tp)).clamp(0.0, 1.0);
                self.vel.push(vp + (velocity - vp) * s);
                self.next_resp += self.dt_resp;
            }
        }
        self.prev_vel = Some((v.t, velocity));
    }
    pub(crate) fn acceleration(&self) -> Vec<f64> {
        self.vel
            .windows(2)
            .map(|w| (w[1] - w[0]) / self.dt_resp)
            .collect()
    }
}

/// Radius of the bouncing sphere, m (the 50 mm sphere of thesis Figure 2.7).
pub(crate) const SPHERE_RADIUS_M: f64 = 0.05;
/// Drop height of the sphere's lowest point above the floor, m.
pub(crate) const SPHERE_DROP_M: f64 = 0.1;

/// Hertz contact of a 7075 sphere (R = 50 mm) on a 7075 half-space: k = 4/3 E* sqrt(R)
/// (eq. 2.5-2.10, E = 72 GPa, nu = 0.33 on both sides), e = 1.5, no damping (elastic bounces,
/// so the time-averaged normal force over whole bounces equals m g).
pub(crate) fn sphere_impact() -> ImpactParams {
    use railwear::thesis::{POISSON_RATIO_7075, YOUNGS_MODULUS_7075_PA};
    let e_star = 1.0 / (2.0 * (1.0 - POISSON_RATIO_7075.powi(2)) / YOUNGS_MODULUS_7075_PA);
    let k_si = 4.0 / 3.0 * e_star * SPHERE_RADIUS_M.sqrt();
    let k_adams = k_si * 1e-3f64.powf(1.5);
    let mut p = ImpactParams::from_adams_units(k_adams, 1.5, 0.0, 0.0);
    p.full_damping_depth = 1e-9;
    p
}

pub(crate) fn sphere_bounce(
    kind: IntegratorKind,
    duration: f64,
    budget: Duration,
) -> Outcome<SphereRun> {
    let (sys, mut y) = railwear::validation::sphere_on_floor(SPHERE_RADIUS_M, sphere_impact(), 0.0);
    write_state(
        &mut y,
        0,
        &Isometry3::translation(0.0, SPHERE_RADIUS_M + SPHERE_DROP_M, 0.0),
        Vector3::zeros(),
        Vector3::zeros(),
    );
    let settings = IntegratorSettings {
        kind,
        tolerances: Tolerances::default(),
        initial_step_s: 1e-6,
        max_step_s: 1e-3,
        min_step_s: 1e-15,
        ..IntegratorSettings::default()
    };
    let mut means = StepMeans::new(0.0, 2000.0);
    let (control, reached, stop) = budget_control(budget);
    let res = simulate(
        &sys,
        &mut y,
        0.0,
        duration,
        settings,
        DivergenceLimits::default(),
        &control,
        &mut |v: &StepView| means.push(v, v.state[8]),
    );
    let timed_out = stop();
    match res {
        Ok(stats) => {
            let acc = means.acceleration();
            Outcome::Done(SphereRun {
                simulated_s: duration,
                wall_s: stats.wall_s,
                accepted: stats.integrator.accepted,
                rejected: stats.integrator.rejected,
                mean_normal_force_n: means.normal_int / duration,
                mean_normal_slip_power_w: means.power_int / duration,
                vdv_y: vibration_dose_value_uniform(&acc, means.dt_resp).ok(),
            })
        }
        Err(SimError::Cancelled { time_s }) if timed_out => Outcome::Timeout {
            simulated_s: time_s.max(f64::from_bits(reached.load(Ordering::Relaxed))),
        },
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

pub(crate) const ENGINE_COLUMNS: &[(&str, &str)] = &[
    ("case", "case"),
    ("integrator", "integrator"),
    ("tolerance", "tolerance"),
    ("real_time_factor", "real-time factor"),
    ("steps_per_s", "steps/s"),
    ("accepted", "accepted"),
    ("rejected", "rejected"),
    ("mean_normal_force_n", "mean normal force N"),
    ("mean_normal_slip_power_w", "mean N·\\|v_slip\\| W"),
    ("vdv_ratio", "VDV/VDV_trbdf2"),
];

pub(crate) fn status_row(case: &str, kind: &str, tol: &str, status: String) -> Vec<Cell> {
    let mut r = vec![Cell::text(case), Cell::text(kind), Cell::text(tol)];
    r.push(Cell::text(status));
    r.extend((0..6).map(|_| Cell::text("-")));
    r
}

pub(crate) fn engine(
    configs_dir: &Path,
    settle: f64,
    window: f64,
    budget_s: f64,
    sphere_duration: f64,
    integrators: &str,
) -> Result<Vec<Table>> {
    if !(settle >= 0.0 && window > 0.0 && budget_s > 0.0 && sphere_duration > 0.0) {
        bail!("--settle must be >= 0 and --window, --budget, --sphere-duration > 0");
    }
    let kinds: Vec<IntegratorKind> = integrators
        .split(',')
        .map(kind_from_name)
        .collect::<Result<_>>()?;
    let budget = Duration::from_secs_f64(budget_s);
    let mut table = Table::new(
        format!(
            "Engine: real-time factor and VDV per integrator (one thread; rattle box C settle {settle} s + window {window} s; sphere {sphere_duration} s)"
        ),
        ENGINE_COLUMNS,
    );
    // Rattle box case C.
    let mut box_rows: Vec<(IntegratorKind, Vec<Cell>, Option<f64>)> = Vec::new();
    for &kind in &kinds {
        let (_, model, options) = rattle_box_c(configs_dir, settle, window, kind)?;
        let tol = tolerance_text(&options.integrator.tolerances);
        eprintln!("engine: rattle box C, {} ...", kind.name());
        match run_model_budget(&model, &options, budget) {
            Outcome::Done(r) => {
                let acc: Vec<f64> = r.response_acceleration.iter().map(|a| a[0]).collect();
                let vdv = vibration_dose_value_uniform(&acc, 1.0 / r.response_rate_hz).ok();
                let wall = r.wall_s.max(1e-9);
                box_rows.push((
                    kind,
                    vec![
                        Cell::text("rattle box C"),
                        Cell::text(kind.name()),
                        Cell::text(tol),
                        Cell::Num(model.end_time_s / wall),
                        Cell::Num(r.integrator.accepted as f64 / wall),
                        Cell::Int(r.integrator.accepted),
                        Cell::Int(r.integrator.rejected),
                        Cell::Num(r.mean_normal_force_n),
                        Cell::Num(r.mean_normal_slip_power_w),
                    ],
                    vdv,
                ));
            }
            Outcome::Timeout { simulated_s } => box_rows.push((
                kind,
                status_row(
                    "rattle box C",
                    kind.name(),
                    &tol,
                    format!("timeout ({budget_s} s wall budget, reached t = {simulated_s:.4} s)"),
                ),
                None,
            )),
            Outcome::Failed(msg) => box_rows.push((
                kind,
                status_row("rattle box C", kind.name(), &tol, format!("failed: {msg}")),
                None,
            )),
        }
    }
    push_with_vdv_ratio(&mut table, box_rows);
    // Bouncing sphere.
    let mut sphere_rows = Vec::new();
    let tol = tolerance_text(&Tolerances::default());
    for &kind in &kinds {
        eprintln!("engine: bouncing sphere, {} ...", kind.name());
        match sphere_bounce(kind, sphere_duration, budget) {
            Outcome::Done(s) => {
                let wall = s.wall_s.max(1e-9);
                sphere_rows.push((
                    kind,
                    vec![
                        Cell::text("sphere bounce (Hertz)"),
                        Cell::text(kind.name()),
                        Cell::text(tol.clone()),
                        Cell::Num(s.simulated_s / wall),
                        Cell::Num(s.accepted as f64 / wall),
                        Cell::Int(s.accepted),
                        Cell::Int(s.rejected),
                        Cell::Num(s.mean_normal_force_n),
                        Cell::Num(s.mean_normal_slip_power_w),
                    ],
                    s.vdv_y,
                ));
            }
            Outcome::Timeout { simulated_s } => sphere_rows.push((
                kind,
                status_row(
                    "sphere bounce (Hertz)",
                    kind.name(),
                    &tol,
                    format!("timeout ({budget_s} s wall budget, reached t = {simulated_s:.4} s)"),
                ),
                None,
            )),
            Outcome::Failed(msg) => sphere_rows.push((
                kind,
                status_row(
                    "sphere bounce (Hertz)",
                    kind.name(),
                    &tol,
                    format!("failed: {msg}"),
                ),
                None,
            )),
        }
    }
    push_with_vdv_ratio(&mut table, sphere_rows);
    let mass = railwear::thesis::DENSITY_7075_KG_PER_M3 * 4.0 / 3.0
        * std::f64::consts::PI
        * SPHERE_RADIUS_M.powi(3);
    table.note(
        "rattle box C: configs/rattle-box-c.toml (Table 5.2 contact, 15 g 20 Hz), tracks not \
         recorded; real-time factor = (settle + window) / wall; steps/s = accepted steps / wall; \
         means over the window only; VDV (eq. 2.51) of the cube's x acceleration over the window",
    );
    table.note(format!(
        "sphere: R = 50 mm 7075 sphere dropped {SPHERE_DROP_M} m onto a half-space, Hertz \
         k = 4/3 E* sqrt(R), e = 1.5, no damping (elastic); means over the whole run, VDV of the \
         vertical acceleration; over whole bounces the mean normal force is m g = {:.3} N",
        mass * railwear::units::STANDARD_GRAVITY
    ));
    table.note("timeout = cancelled through RunControl after the wall budget (--budget)");
    table.note(machine_note());
    Ok(vec![table])
}

/// Appends rows with the VDV column normalised to the trbdf2 row of the same case.
pub(crate) fn push_with_vdv_ratio(
    table: &mut Table,
    rows: Vec<(IntegratorKind, Vec<Cell>, Option<f64>)>,
) {
    let reference = rows
        .iter()
        .find(|(k, _, _)| *k == IntegratorKind::Trbdf2)
        .and_then(|(_, _, v)| *v);
    for (_, mut cells, vdv) in rows {
        // Status rows (timeout, failure) already fill every column.
        if cells.len() == ENGINE_COLUMNS.len() {
            table.row(cells);
            continue;
        }
        let ratio = match (vdv, reference) {
            (Some(v), Some(r)) if r > 0.0 => Some(v / r),
            _ => None,
        };
        cells.push(Cell::opt(ratio));
        table.row(cells);
    }
}
