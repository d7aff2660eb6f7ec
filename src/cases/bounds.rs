//! Physical bounds on every number a case can carry (issue 29: no silent nonsense).
//!
//! A case passes its model's own rules (`models::spec`: positive sizes, unit axes, the cube fits
//! the tube) and then these: each number lies in a range with a physical reason, so a typing
//! error (a friction coefficient of 1e6, an amplitude of 1e308 g) is refused at submit with a
//! 422 naming the field instead of running into NaN. The ranges are deliberately wide: they
//! bound what is physically possible for a captive-carry launcher or a shaker test, not what
//! is usual; the thesis' values sit well inside every one of them.
//!
//! The table is keyed by the field's name as case files write it (the last key of its path:
//! `mu_static`, `amplitude_g`), because the names carry their units; the few names shared by
//! two tables (`duration_s` of the run and of a synthesised record, `mass_kg` of the missile
//! and of the latch) get one range that holds for both. A rule may be restricted to one `kind`
//! of a tagged table (the legacy wear law's coefficients) and to one position of a tuple (a
//! PSD breakpoint is `[frequency Hz, level g²/Hz]`). A test walks every numeric field of every
//! reference config and of each optional table and fails on a field without a rule, and on a
//! rule no field uses.
//!
//! Over 700 lines on purpose: the table is one entry per field with its reason, and reads (and
//! is reviewed) best as one list beside the walk that applies it.

use super::limits;
use crate::field_error::FieldError;
use crate::models::spec::CaseSpec;
use serde_json::Value;

/// A closed or half-open range of one field, with its unit and the physical reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// The field's name as written in case files (last key of its path).
    pub key: &'static str,
    /// Position in a tuple array (`psd_breakpoints`, `samples`); `None`: every element.
    pub component: Option<usize>,
    /// Only inside a table whose `kind` is this (tagged wear laws); `None`: any table.
    pub kind: Option<&'static str>,
    /// Lower end.
    pub min: f64,
    /// Whether `min` itself is refused.
    pub min_open: bool,
    /// Upper end (inclusive).
    pub max: f64,
    /// Unit of the field, as its name says.
    pub unit: &'static str,
    /// Why values outside the range are not physical.
    pub reason: &'static str,
}

impl Bound {
    /// Whether `v` is a finite number inside the range.
    pub fn admits(&self, v: f64) -> bool {
        v.is_finite()
            && v <= self.max
            && if self.min_open {
                v > self.min
            } else {
                v >= self.min
            }
    }

    /// The rule in words: `must lie in [min, max] unit (reason)`.
    pub fn rule(&self) -> String {
        let open = if self.min_open { "(" } else { "[" };
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "must lie in {open}{:e}, {:e}]{unit}: {}",
            self.min, self.max, self.reason
        )
    }
}

const fn b(
    key: &'static str,
    min: f64,
    max: f64,
    unit: &'static str,
    reason: &'static str,
) -> Bound {
    Bound {
        key,
        component: None,
        kind: None,
        min,
        min_open: false,
        max,
        unit,
        reason,
    }
}

const fn open_min(mut bound: Bound) -> Bound {
    bound.min_open = true;
    bound
}

const fn component(mut bound: Bound, index: usize) -> Bound {
    bound.component = Some(index);
    bound
}

const fn of_kind(mut bound: Bound, kind: &'static str) -> Bound {
    bound.kind = Some(kind);
    bound
}

const LENGTH: &str = "sizes from 1 µm (below the roughness of machined aluminium) to 10 m \
                      (longer than any air-launched store; the Hellfire is 1.63 m)";
const POSITION: &str = "positions within 10 m of their frame's origin: the launcher and its \
                        missile span under 2 m";
const SPRING_STIFFNESS: &str = "springs up to 1 GN/m, stiffer than the rail's own aluminium \
                                section; 0 is no spring";
const FORCE: &str = "spring and point forces up to 100 kN: 226 g on a 45 kg missile";
const FREQUENCY: &str = "vibration between 0.1 Hz (below it a tone is a manoeuvre) and 5 kHz \
                         (above it the rail's structural modes, not rigid contact, decide; \
                         MIL-STD-810G 514.6 stops at 2 kHz)";
const CUTOFF_FREQUENCY: &str = "a drift cutoff between 0.01 Hz and 1 kHz: it must sit below \
                                the content it keeps";
const SEED: &str = "seeds below 2^53 read back exactly from JSON (see limits::MAX_SEED)";
const LAUNCHER_DIMENSION: &str = "rail and shoe section letters (eq. 6.1-6.2) from 10 µm (a \
                                  machining tolerance) to 1 m; the thesis' are 9.5-38 mm";
const CONTACT_STIFFNESS: &str = "IMPACT stiffness from 1e-3 to 1e8 N/mm^e: the thesis uses \
                                 1e3-1e4; stiffer laws put contact time constants below 1 ns";
const TRANSITION_SPEED: &str = "friction transition speeds from 1 µm/s to 1 m/s (Table 5.2: \
                                6.46 and 12 mm/s); above 1 m/s every slip of a rattle is \
                                stiction";
const MU: &str = "friction coefficients of dry engineering pairs lie below 1.3 (clean \
                  aluminium); 2 bounds every real pair, Table 5.2 gives 0.18";

/// Every bound, the more specific rules (a tuple position, a table kind) before the general.
pub static BOUNDS: &[Bound] = &[
    // Run control (mirrors `limits`, checked first by `check_simulation_bounds`).
    b(
        "settle_s",
        0.0,
        limits::MAX_SETTLE_S,
        "s",
        "a settle of up to ten minutes, past the contact creep time constant (thesis: 2 s)",
    ),
    b(
        "duration_s",
        limits::MIN_RECORD_INTERVAL_S,
        limits::MAX_DURATION_S,
        "s",
        "from one record interval (1 µs) to 24 h of simulated time (thesis: 12 h at most); \
         also the length of a synthesised random record",
    ),
    b(
        "rel_tolerance",
        limits::REL_TOLERANCE_RANGE.0,
        limits::REL_TOLERANCE_RANGE.1,
        "",
        "looser than 10 % is no error control; tighter than 1e-10 is below double precision",
    ),
    b(
        "abs_tolerance_m",
        limits::ABS_TOLERANCE_M_RANGE.0,
        limits::ABS_TOLERANCE_M_RANGE.1,
        "m",
        "coarser than 0.1 mm misses the tight rail's 0.2 mm clearance; finer than 1e-15 m is \
         below double precision on metres",
    ),
    b(
        "record_interval_s",
        limits::MIN_RECORD_INTERVAL_S,
        limits::MAX_DURATION_S,
        "s",
        "1 µs resolves a 500 Hz excitation 2000 times over",
    ),
    b(
        "energy_rel_tolerance",
        0.0,
        0.5,
        "",
        "above 50 % the energy account's quadrature error is as large as the work it checks; \
         0 switches the check off",
    ),
    b(
        "contact_points_per_edge",
        crate::geometry::lattice::POINTS_PER_EDGE_RANGE.0 as f64,
        crate::geometry::lattice::POINTS_PER_EDGE_RANGE.1 as f64,
        "",
        "2 points per edge are the corners; beyond 33 the cost grows with no change in the \
         resolved face law",
    ),
    b("seed", 0.0, limits::MAX_SEED as f64, "", SEED),
    // Material (wear::material::Material).
    b(
        "density_kg_per_m3",
        limits::DENSITY_KG_M3_RANGE.0,
        limits::DENSITY_KG_M3_RANGE.1,
        "kg/m³",
        "from polymers to the densest metals (osmium 22 590 kg/m³)",
    ),
    b(
        "yield_strength_pa",
        1.0e6,
        1.0e10,
        "Pa",
        "from soft polymers (1 MPa) to above the strongest steels (maraging 2.5 GPa)",
    ),
    b(
        "youngs_modulus_pa",
        1.0e7,
        1.2e12,
        "Pa",
        "from elastomers (10 MPa) to diamond (1.2 TPa)",
    ),
    open_min(b(
        "poisson_ratio",
        -1.0,
        0.5,
        "",
        "an isotropic solid is stable only for -1 < ν <= 0.5",
    )),
    b(
        "brinell_hardness",
        1.0,
        1000.0,
        "HB",
        "from lead (about 5 HB) to above hardened tool steel (about 700 HB)",
    ),
    // Rattle box (chapter 5).
    b("cube_side_m", 1.0e-6, 10.0, "m", LENGTH),
    b(
        "cube_mass_kg",
        1.0e-4,
        1.0e4,
        "kg",
        "from 0.1 g (a chip, not a body) to 10 t (the heaviest air-launched stores)",
    ),
    b("tube_inner_side_m", 1.0e-6, 10.0, "m", LENGTH),
    b("tube_length_m", 1.0e-6, 10.0, "m", LENGTH),
    b(
        "edge_radius_m",
        0.0,
        0.1,
        "m",
        "roundovers are fractions of a millimetre (thesis 5.4: 0.508 mm); a 10 cm radius is a \
         piece, not a roundover",
    ),
    // Contact (Tables 4.1, 5.2, 6.2, ADAMS units).
    b(
        "stiffness_n_per_mm_e",
        1.0e-3,
        1.0e8,
        "N/mm^e",
        CONTACT_STIFFNESS,
    ),
    b(
        "exponent",
        1.0,
        4.0,
        "",
        "force exponents of contact laws lie between 1 (flat punch) and about 3 (rough \
         surfaces, Kogut-Etsion fits); Hertz gives 1.5, the thesis 2; at 4 the force at the \
         0.01 mm damping depth is 1e-8 of the linear law's",
    ),
    b(
        "damping_ns_per_mm",
        0.0,
        1.0e5,
        "N·s/mm",
        "up to 200 times the thesis' 500 N·s/mm; more makes every impact plastic",
    ),
    open_min(b(
        "penetration_depth_mm",
        0.0,
        1.0,
        "mm",
        "full damping within 1 mm of penetration (thesis: 0.01 mm); deeper than the tight \
         rail's whole clearance is no ramp",
    )),
    // Friction (eq. 4.5, Tables 4.2, 5.2, 6.1).
    b("mu_static", 0.0, 2.0, "", MU),
    b("mu_dynamic", 0.0, 2.0, "", MU),
    b(
        "stiction_transition_speed_mm_per_s",
        1.0e-3,
        1.0e3,
        "mm/s",
        TRANSITION_SPEED,
    ),
    b(
        "friction_transition_speed_mm_per_s",
        1.0e-3,
        1.0e3,
        "mm/s",
        TRANSITION_SPEED,
    ),
    // Wear laws (eq. 3.8, 3.10-3.15; the legacy appendix C code first: its C1-C3 act on N).
    of_kind(
        b(
            "c1",
            0.0,
            1.0e-10,
            "",
            "the appendix code's C1 (Table 4.3: 2.4e-15); the law is kept only to reproduce \
             the thesis",
        ),
        "legacy_appendix",
    ),
    of_kind(
        b(
            "c2",
            0.0,
            100.0,
            "",
            "the appendix code's C2 (Table 4.3: 6.32; 0 gives no wear, as in the code)",
        ),
        "legacy_appendix",
    ),
    of_kind(
        b(
            "c3",
            -1.0e-7,
            1.0e-7,
            "",
            "the appendix code's C3, scaled by 1e-3 in the code (Table 4.3: -9.5e-16)",
        ),
        "legacy_appendix",
    ),
    b(
        "c1",
        0.0,
        1.0e-10,
        "m²/N per Pa^(1/C2)",
        "wear grows with pressure (Table 4.3: C1 = 2.4e-15 > 0); at 1 Pa C1 is the wear \
         coefficient itself, which stays below 1e-10 m²/N (see coefficient_m2_per_n)",
    ),
    b(
        "c2",
        0.5,
        100.0,
        "",
        "the pressure exponent 1/C2 lies between 0.01 and 2 (Table 4.3: C2 = 6.32); a \
         coefficient growing faster than pressure squared is no fitted wear law",
    ),
    b(
        "c3",
        -1.0e-10,
        1.0e-10,
        "m²/N",
        "an offset of the wear coefficient, no larger than the largest coefficient (Table \
         4.3: -9.5e-16)",
    ),
    b(
        "cutoff_pressure_pa",
        1.0e5,
        limits::MAX_CUTOFF_PRESSURE_PA,
        "Pa",
        "from atmospheric pressure (below it every contact is above the cutoff) to 10 GPa, \
         above the hardness of any engineering alloy (eq. 3.11: 2 S_y = 870 MPa for 7075)",
    ),
    b(
        "coefficient_m2_per_n",
        0.0,
        1.0e-10,
        "m²/N",
        "Archard's k/H: severe adhesive wear (k about 1e-2) on the softest metals (H about \
         1e8 Pa) gives 1e-10 m²/N",
    ),
    // Wear mechanisms beside the law (`wear.mechanism`, what a diagnosis fits; the gap
    // effect library gives each parameter's source).
    of_kind(
        b(
            "ratio",
            0.0,
            1000.0,
            "",
            "K above the cutoff as a multiple of K at it: up to the thousandfold jump from mild \
             to severe wear (Archard 1953; the library's wear_above_cutoff bound)",
        ),
        "wear_above_cutoff",
    ),
    b(
        "k_add_m2_per_n",
        0.0,
        1.0e-10,
        "m²/N",
        "an added k/H: severe adhesive wear (k about 1e-2) on the softest metals (H about 1e8 \
         Pa) gives 1e-10 m²/N, as for the Archard coefficient",
    ),
    b(
        "min_pressure_pa",
        0.0,
        limits::MAX_CUTOFF_PRESSURE_PA,
        "Pa",
        "a pressure threshold: no contact pressure exceeds 10 GPa, above any alloy's hardness",
    ),
    b(
        "min_slip_m_s",
        0.0,
        100.0,
        "m/s",
        "a slip-speed threshold: a carried missile's shoes slide at mm/s to m/s",
    ),
    b(
        "k_energy_m3_per_j",
        0.0,
        1.0e-11,
        "m³/J",
        "wear volume per joule of impact damping: dissipated-energy wear measures 1e-15 to \
         1e-13 m³/J (Fouvry et al. 2003); Archard's range over H mu bounds it at 1.5e-11",
    ),
    b(
        "min_normal_speed_m_s",
        0.0,
        10.0,
        "m/s",
        "a normal-speed threshold of impact wear: rattling impacts reach cm/s to m/s",
    ),
    b(
        "pressure_ratio_to_yield",
        0.1,
        10.0,
        "",
        "a pressure threshold as a multiple of S_y: plastic flow starts near 1 and the \
         hardness is about 3 S_y (Tabor)",
    ),
    of_kind(
        b(
            "share",
            0.0,
            1.0,
            "",
            "a share of the wear evaluated at the points' own pressures, 0 to all of it",
        ),
        "local_pressure",
    ),
    b(
        "breakthrough_slip_m",
        0.0,
        1.0e9,
        "m",
        "the slip distance an anodic coating lasts: from new to beyond a million km of \
         sliding",
    ),
    b(
        "speed_unit_m_s",
        1.0e-6,
        1.0,
        "m/s",
        "the exported slip-speed unit: µm/s to m/s (ADAMS: mm/s, 1e-3)",
    ),
    b(
        "output_unit_m3",
        1.0e-27,
        1.0,
        "m³",
        "the appendix code's output unit: cubic nanometres to cubic metres (thesis: µm³, \
         1e-18)",
    ),
    b("fraction_to_a", 0.0, 1.0, "", "a share of the wear volume"),
    // Launcher (chapter 6).
    b("a_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("f_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("g_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("h_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("i_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("j_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("k_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("l_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("m_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("n_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("o_shoe_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("b_rail_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("n_rail_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("q_rail_mm", 0.01, 1000.0, "mm", LAUNCHER_DIMENSION),
    b("channel_length_m", 1.0e-6, 10.0, "m", LENGTH),
    b("lip_thickness_m", 1.0e-6, 10.0, "m", LENGTH),
    b("bottom_half_width_m", 1.0e-6, 10.0, "m", LENGTH),
    b("length_m", 1.0e-6, 10.0, "m", LENGTH),
    b("diameter_m", 1.0e-6, 10.0, "m", LENGTH),
    b("half_extents_m", 1.0e-6, 10.0, "m", LENGTH),
    b("engagement_smoothing_m", 1.0e-6, 10.0, "m", LENGTH),
    b("channel_centre_z_m", -10.0, 10.0, "m", POSITION),
    b("lip_top_y_m", -10.0, 10.0, "m", POSITION),
    b("com_z_in_rail_m", -10.0, 10.0, "m", POSITION),
    b("z_in_rail_m", -10.0, 10.0, "m", POSITION),
    b("reach_below_roof_m", -10.0, 10.0, "m", POSITION),
    b("centre_m", -10.0, 10.0, "m", POSITION),
    b("head_base_in_missile_m", -10.0, 10.0, "m", POSITION),
    b("com_in_rail_m", -10.0, 10.0, "m", POSITION),
    b("hinge_point_in_rail_m", -10.0, 10.0, "m", POSITION),
    b("point_on_rail_m", -10.0, 10.0, "m", POSITION),
    b("point_on_latch_m", -10.0, 10.0, "m", POSITION),
    b("point_in_missile_m", -10.0, 10.0, "m", POSITION),
    b("stations", -10.0, 10.0, "m", POSITION),
    b(
        "hinge_axis",
        -1.0,
        1.0,
        "",
        "the components of a unit vector",
    ),
    b(
        "direction_in_rail",
        -1.0,
        1.0,
        "",
        "the components of a unit vector",
    ),
    b(
        "mass_kg",
        1.0e-4,
        1.0e4,
        "kg",
        "from 0.1 g (a chip, not a body) to 10 t (the heaviest air-launched stores; the \
         Hellfire is 45 kg)",
    ),
    b(
        "inertia_kg_m2",
        1.0e-12,
        1.0e5,
        "kg·m²",
        "from a 1 mm part to a 10 t store 10 m long (m L²/12 = 8e4 kg·m²)",
    ),
    b("stiffness_n_per_m", 0.0, 1.0e9, "N/m", SPRING_STIFFNESS),
    b(
        "damping_ns_per_m",
        0.0,
        1.0e6,
        "N·s/m",
        "spring damping up to 1 MN·s/m, which locks a 45 kg missile within 50 µs",
    ),
    b("preload_n", 0.0, 1.0e5, "N", FORCE),
    b("force_n", 0.0, 1.0e5, "N", FORCE),
    // Excitation (crate::excitation).
    b("frequency_hz", 0.1, 5000.0, "Hz", FREQUENCY),
    b(
        "amplitude_g",
        0.0,
        200.0,
        "g",
        "shakers reach about 100 g sine and captive-carry profiles stay below 10 g (thesis: \
         15 g on the rattle box); above 200 g is shock, not vibration",
    ),
    b("phase_deg", -360.0, 360.0, "°", "one turn either way"),
    b(
        "seconds",
        0.0,
        limits::MAX_SETTLE_S,
        "s",
        "a ramp-in no longer than the longest settle",
    ),
    b(
        "cycles",
        0.0,
        1000.0,
        "cycles",
        "a ramp-in of up to 1000 cycles of the lowest frequency (default 3)",
    ),
    component(b("psd_breakpoints", 0.1, 5000.0, "Hz", FREQUENCY), 0),
    component(
        open_min(b(
            "psd_breakpoints",
            0.0,
            10.0,
            "g²/Hz",
            "PSD levels above 0 and up to 10 g²/Hz (140 g rms over 2 kHz); MIL-STD-810G \
             helicopter levels stay below 0.1 g²/Hz",
        )),
        1,
    ),
    b(
        "sample_rate_hz",
        1.0,
        1.0e6,
        "Hz",
        "a record sampled at 1 Hz to 1 MHz (4x the highest frequency is enough)",
    ),
    b("low_cutoff_hz", 0.01, 1000.0, "Hz", CUTOFF_FREQUENCY),
    b("highpass_hz", 0.01, 1000.0, "Hz", CUTOFF_FREQUENCY),
    component(
        b(
            "samples",
            0.0,
            limits::MAX_DURATION_S + limits::MAX_SETTLE_S,
            "s",
            "sample times within the longest run",
        ),
        0,
    ),
    b(
        "samples",
        -1.0e4,
        1.0e4,
        "g or m/s²",
        "measured accelerations up to 1e4 in either unit: beyond it a record is a unit error \
         or a shock",
    ),
];

/// Bounds on the numbers of a calibration data set (`calibrate` jobs, thesis 4.3-4.4): the
/// torque records of the rotating-cup test and the wear tests' records.
pub static CALIBRATION_BOUNDS: &[Bound] = &[
    b(
        "polar_inertia_kg_m2",
        1.0e-9,
        1.0e3,
        "kg·m²",
        "a fixture's rotating parts, from a 1 g cup to a 1 t turntable",
    ),
    b(
        "mean_radius_m",
        1.0e-5,
        10.0,
        "m",
        "contact radii from 10 µm to 10 m",
    ),
    b(
        "time_s",
        0.0,
        limits::MAX_DURATION_S,
        "s",
        "a test record within 24 h",
    ),
    b(
        "angle_rad",
        -1.0e7,
        1.0e7,
        "rad",
        "1.6 million turns: a day at 20 rev/s",
    ),
    b(
        "angular_velocity_rad_s",
        -1.0e4,
        1.0e4,
        "rad/s",
        "up to 95 000 rpm, past any friction rig's spindle",
    ),
    b(
        "normal_load_n",
        0.0,
        1.0e6,
        "N",
        "a compressive load up to 1 MN, a large press",
    ),
    b(
        "input_torque_n_m",
        -1.0e5,
        1.0e5,
        "N·m",
        "torques up to 100 kN·m, past any friction rig's drive",
    ),
    b(
        "contact_pressure_pa",
        0.0,
        limits::MAX_CUTOFF_PRESSURE_PA,
        "Pa",
        "compressive pressures up to 10 GPa, above any engineering alloy's hardness",
    ),
    b(
        "sliding_distance_m",
        0.0,
        1.0e7,
        "m",
        "up to 10 000 km of sliding",
    ),
    b(
        "wear_mass_kg",
        0.0,
        1.0,
        "kg",
        "wear of a test specimen, up to 1 kg",
    ),
];

/// Checks every number of a calibration data set (`friction` or `wear_law` of a calibrate
/// job, at `prefix`) against [`CALIBRATION_BOUNDS`]; fields without a bound there are checked
/// elsewhere (density, cutoff) or are not numbers.
pub fn check_calibration_value(value: &Value, prefix: &str) -> Result<(), FieldError> {
    walk_leaves(value, prefix, &mut |leaf| {
        let Some(bound) = CALIBRATION_BOUNDS.iter().find(|b| b.key == leaf.key) else {
            return Ok(());
        };
        match leaf.value {
            Value::Number(n) if bound.admits(n.as_f64().unwrap_or(f64::NAN)) => Ok(()),
            Value::Null => Ok(()),
            other => Err(FieldError::new(
                leaf.path,
                format!("{}, got {other}", bound.rule()),
            )),
        }
    })
}

/// Longest text field of a case (names, labels, paths), characters: a name is read on a plot
/// or in a list; 256 characters hold any path in `configs/`.
pub const MAX_TEXT_CHARS: usize = 256;
/// Longest case description, characters: one paragraph with its thesis source.
pub const MAX_DESCRIPTION_CHARS: usize = 2000;
/// Most tones of one excitation: a rotorcraft profile has its 1P tone and a dozen harmonics.
pub const MAX_TONES: usize = 64;
/// Most PSD breakpoints: MIL-STD-810G's tables have fewer than 20.
pub const MAX_PSD_BREAKPOINTS: usize = 256;
/// Largest wear coefficient any wear law may reach below its cutoff, m²/N: Archard's k/H for
/// severe adhesive wear (k about 1e-2) of the softest metals (H about 1e8 Pa). Table 4.3 at
/// its 870 MPa cutoff gives 6.1e-14.
pub const MAX_WEAR_COEFFICIENT_M2_PER_N: f64 = 1.0e-10;

/// The bound of a numeric field named `key`, at tuple position `component`, in a table of
/// `kind` (first match of [`BOUNDS`]).
pub fn bound_for(
    key: &str,
    component: Option<usize>,
    kind: Option<&str>,
) -> Option<&'static Bound> {
    BOUNDS.iter().find(|b| {
        b.key == key
            && (b.component.is_none() || b.component == component)
            && (b.kind.is_none() || b.kind == kind)
    })
}

/// One scalar of a JSON document with where it sits.
#[derive(Debug, Clone, Copy)]
pub struct Leaf<'a> {
    /// Dotted path, `a.b[2].c` (as `serde_path_to_error` writes it).
    pub path: &'a str,
    /// The last object key above it.
    pub key: &'a str,
    /// The last array index below that key (tuple position), if any.
    pub component: Option<usize>,
    /// The `kind` of the innermost table holding it.
    pub kind: Option<&'a str>,
    /// The value.
    pub value: &'a Value,
}

/// Calls `visit` on every scalar of `value` (`prefix` is the path of `value` itself).
pub fn walk_leaves<E>(
    value: &Value,
    prefix: &str,
    visit: &mut dyn FnMut(Leaf) -> Result<(), E>,
) -> Result<(), E> {
    fn go<E>(
        value: &Value,
        path: &mut String,
        key: &str,
        component: Option<usize>,
        kind: Option<&str>,
        visit: &mut dyn FnMut(Leaf) -> Result<(), E>,
    ) -> Result<(), E> {
        match value {
            Value::Object(map) => {
                let inner_kind = map.get("kind").and_then(Value::as_str);
                for (k, v) in map {
                    let len = path.len();
                    if !path.is_empty() {
                        path.push('.');
                    }
                    path.push_str(k);
                    go(v, path, k, None, inner_kind, visit)?;
                    path.truncate(len);
                }
                Ok(())
            }
            Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    let len = path.len();
                    path.push_str(&format!("[{i}]"));
                    go(v, path, key, Some(i), kind, visit)?;
                    path.truncate(len);
                }
                Ok(())
            }
            scalar => visit(Leaf {
                path,
                key,
                component,
                kind,
                value: scalar,
            }),
        }
    }
    let mut path = prefix.to_string();
    let key = prefix.rsplit('.').next().unwrap_or("");
    go(value, &mut path, key, None, None, visit)
}

/// Checks one scalar against its bound (numbers) or the text limits (strings).
fn check_leaf(leaf: Leaf) -> Result<(), FieldError> {
    let bound = bound_for(leaf.key, leaf.component, leaf.kind);
    match (leaf.value, bound) {
        (Value::Number(n), Some(bound)) => {
            let v = n.as_f64().unwrap_or(f64::NAN);
            if bound.admits(v) {
                Ok(())
            } else {
                Err(FieldError::new(
                    leaf.path,
                    format!("{}, got {v}", bound.rule()),
                ))
            }
        }
        // null: an optional field left out (`cube_mass_kg` of a cube weighed by its density).
        (Value::Number(_), None) | (Value::Bool(_), None) | (Value::Null, _) => Ok(()),
        (Value::String(s), None) => {
            let max = if leaf.key == "description" {
                MAX_DESCRIPTION_CHARS
            } else {
                MAX_TEXT_CHARS
            };
            let chars = s.chars().count();
            if chars > max {
                return Err(FieldError::new(
                    leaf.path,
                    format!("has {chars} characters; at most {max} are kept"),
                ));
            }
            let allowed = |c: char| leaf.key == "description" && matches!(c, '\n' | '\t');
            if s.chars().any(|c| c.is_control() && !allowed(c)) {
                return Err(FieldError::new(
                    leaf.path,
                    "must not contain control characters",
                ));
            }
            Ok(())
        }
        (other, Some(bound)) => Err(FieldError::new(
            leaf.path,
            format!(
                "must be a number ({}), got {}",
                bound.rule(),
                match other {
                    Value::String(_) => "a string",
                    _ => "a boolean",
                }
            ),
        )),
        (Value::Array(_) | Value::Object(_), None) => Ok(()),
    }
}

/// Checks every field of `value` (a case or a part of one, at `prefix`) against [`BOUNDS`]
/// and the text limits; the error names the first field out of bounds.
pub fn check_value(value: &Value, prefix: &str) -> Result<(), FieldError> {
    walk_leaves(value, prefix, &mut check_leaf)
}

/// Array lengths with a physical ceiling (tones, PSD breakpoints) in an excitation table.
fn check_excitation_lengths(excitation: &Value, prefix: &str) -> Result<(), FieldError> {
    for (key, max) in [
        ("tones", MAX_TONES),
        ("psd_breakpoints", MAX_PSD_BREAKPOINTS),
    ] {
        if let Some(items) = excitation.get(key).and_then(Value::as_array) {
            if items.len() > max {
                return Err(FieldError::new(
                    format!("{prefix}.{key}"),
                    format!("has {} entries; at most {max}", items.len()),
                ));
            }
        }
    }
    Ok(())
}

/// The largest wear coefficient the case's law reaches at or below its cutoff, bounded by
/// [`MAX_WEAR_COEFFICIENT_M2_PER_N`] (the field bounds alone let `C1 σ^(1/C2)` reach 1e10).
fn check_wear_law(case: &CaseSpec) -> Result<(), FieldError> {
    use crate::wear::law::WearLaw;
    if let WearLaw::Modified {
        c1,
        c2,
        c3,
        cutoff_pressure_pa,
    } = case.wear.law
    {
        let peak = c1 * cutoff_pressure_pa.powf(1.0 / c2) + c3;
        if !(peak.is_finite() && peak <= MAX_WEAR_COEFFICIENT_M2_PER_N) {
            return Err(FieldError::new(
                "wear.law.c1",
                format!(
                    "gives a wear coefficient C1 σ^(1/C2) + C3 = {peak:e} m²/N at the cutoff \
                     {cutoff_pressure_pa:e} Pa; at most {MAX_WEAR_COEFFICIENT_M2_PER_N:e} m²/N \
                     (severe adhesive wear of the softest metals)"
                ),
            ));
        }
    }
    Ok(())
}

/// Checks every number of `case` against [`BOUNDS`], its texts against the length limits,
/// the excitation's list lengths and the wear law's peak coefficient. `resolved_excitation`
/// is the excitation a profile name stands for (its fields are reported under `excitation`).
/// Errors name the case path (`rattle_box.friction.mu_static`).
pub fn check_case(case: &CaseSpec, resolved_excitation: Option<&Value>) -> Result<(), FieldError> {
    let value = serde_json::to_value(case).map_err(|e| FieldError::new("config", e.to_string()))?;
    check_value(&value, "")?;
    check_excitation_lengths(case.excitation.table(), "excitation")?;
    if let Some(excitation) = resolved_excitation {
        check_value(excitation, "excitation")?;
        check_excitation_lengths(excitation, "excitation")?;
    }
    check_wear_law(case)
}
