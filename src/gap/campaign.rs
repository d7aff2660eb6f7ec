//! Test campaigns: physical tests with their configuration and their measurements.
//!
//! A campaign is a TOML manifest (what a test engineer keeps, with comments) with accelerometer
//! CSV files beside it, or the same content as JSON with the samples inline. Both deserialize
//! into [`Campaign`]; unknown keys are errors at every level. Every quantity carries its unit
//! in its name. See `campaigns/thesis-rattle-box.toml` for a worked example.
//!
//! A test is a reference config (`configs/<config>.toml`) plus overrides (any case key, deep
//! merged as a job's `overrides`), an optional rattle space (rattle box: sets the tube side by
//! eq. 5.1-5.2) and drive (profile, level, frequency), the duration of each increment, the
//! scale resolution and the weighed components; then its specimens (repeats), each with its
//! increments (mass loss per component, mg) and optional accelerometer records.

use super::accel::{self, AccelRecord, ACCEL_COLUMNS};
use super::GapError;
use crate::models::outcome::RunError;
use crate::models::run::BuiltModel;
use crate::models::spec::{CaseSpec, ModelSpecRef};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path};

/// The one campaign format version this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// Longest increment, s: 30 days. Shaker tests run hours per increment (thesis 5.5: 90 min);
/// a month is a typing error.
pub const MAX_INCREMENT_DURATION_S: f64 = 30.0 * 86_400.0;

/// Largest mass loss of one component over one increment, mg: 100 g. Wear increments remove
/// micrograms to milligrams (thesis 5.5: tenths of a milligram over 90 min of shaking); 100 g
/// is twice the whole rattle-box cube. A dynamic component may also not lose more than its own
/// mass (a kinematic one, the tube or the rail, has no mass in the model).
pub const MAX_INCREMENT_MASS_LOSS_MG: f64 = 1.0e5;
/// Finest scale resolution, mg: 0.1 µg, an ultra-microbalance's readability.
pub const MIN_SCALE_RESOLUTION_MG: f64 = 1.0e-4;
/// Highest accelerometer sample rate, Hz: 1 MHz, past any vibration accelerometer's band.
pub const MAX_ACCEL_SAMPLE_RATE_HZ: f64 = 1.0e6;
/// Largest accelerometer noise, m/s² rms: 1000 m/s² (about 100 g) buries any captive-carry
/// signal (MIL-STD-810G helicopter levels stay below 10 g).
pub const MAX_SENSOR_NOISE_M_S2: f64 = 1.0e3;
/// Largest measured acceleration, m/s²: about 1000 g. Captive-carry profiles stay below 10 g
/// and shaker tests below 100 g (thesis 5.5: 15 g); beyond it a record is a unit error (mm/s²
/// for m/s²) or a shock.
pub const MAX_ACCELERATION_M_S2: f64 = 1.0e4;
/// Longest campaign name, characters (shown in lists and reports).
pub const MAX_NAME_CHARS: usize = 200;
/// Longest free text (a description or a source), characters.
pub const MAX_TEXT_CHARS: usize = 10_000;

/// A test campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Campaign {
    /// Format version, 1.
    pub format_version: u32,
    /// Short identifier.
    pub name: String,
    /// What was tested, where and when.
    #[serde(default)]
    pub description: String,
    /// Where the data come from (report, lab book, thesis table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The physical tests.
    pub tests: Vec<CampaignTest>,
}

/// Drive of a test, replacing parts of the config's `[excitation]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// Vibration profile, a file name in `configs/profiles` (without `.toml`); replaces the
    /// config's excitation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<String>,
    /// Peak acceleration of the drive tone, g (single-tone sine drives only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level_g: Option<f64>,
    /// Frequency of the drive tone, Hz (single-tone sine drives only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f64>,
}

/// One physical test configuration with its repeats.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignTest {
    /// Identifier, unique in the campaign (letters, digits, `-`, `_`).
    pub id: String,
    /// Reference config name (`configs/<config>.toml`).
    pub config: String,
    /// What differs from the reference, in words.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Case keys deep-merged into the config (as a job's `overrides`), e.g. measured
    /// dimensions `{rattle_box = {tube_inner_side_m = 0.03181}}`.
    #[serde(default = "empty_object", skip_serializing_if = "is_empty_object")]
    pub overrides: serde_json::Value,
    /// Rattle space k_rs (eq. 5.1-5.2), rattle box only: sets the tube inner side to
    /// `cube_side / sqrt(k_rs)` and relabels the case `custom`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rattle_space: Option<f64>,
    /// Drive profile and level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive: Option<DriveSpec>,
    /// Excited duration of each increment, s.
    pub increment_duration_s: f64,
    /// Resolution of the scale the components were weighed on, mg.
    pub scale_resolution_mg: f64,
    /// Weighed components: body names of the model (rattle box: `cube`, `tube`).
    pub components: Vec<String>,
    /// Specimens (repeats of the test), each with its increments.
    pub specimens: Vec<Specimen>,
}

/// One specimen (a repeat) of a test. Its id is unique within its test; two tests may use
/// the same id (each test is its own configuration, and a specimen is known by test and id:
/// `A/s1` and `B/s1` are two specimens).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Specimen {
    /// Identifier, unique in its test (letters, digits, `-`, `_`).
    pub id: String,
    /// Increments run on this specimen, in order.
    pub increments: Vec<Increment>,
    /// Accelerometer records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub accelerometers: Vec<AccelRecord>,
}

/// One increment: the mass each weighed component lost over it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Increment {
    /// Mass loss per component, mg (>= 0). A component not listed was not weighed; a skeleton
    /// campaign (for `railwear rig`) leaves this empty.
    #[serde(default)]
    pub mass_loss_mg: BTreeMap<String, f64>,
}

fn empty_object() -> serde_json::Value {
    serde_json::Value::Object(Default::default())
}

fn is_empty_object(v: &serde_json::Value) -> bool {
    v.as_object().is_some_and(|m| m.is_empty())
}

fn plain_id(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

impl Campaign {
    /// Parses a TOML manifest. Accelerometer CSV files are read from `base_dir` (relative paths
    /// without `..`). Not yet validated against the configs: see [`Campaign::validate`].
    pub fn from_toml_str(text: &str, base_dir: &Path) -> Result<Self, GapError> {
        let de = toml::Deserializer::new(text);
        let mut campaign: Campaign = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let field = if path == "." { "campaign".into() } else { path };
            GapError::field(field, e.into_inner().message().to_string())
        })?;
        campaign.load_csv_files(base_dir)?;
        Ok(campaign)
    }

    /// Reads and parses a manifest file (CSV files beside it).
    pub fn load(path: &Path) -> Result<Self, GapError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            GapError::field("campaign", format!("cannot read {}: {e}", path.display()))
        })?;
        Self::from_toml_str(&text, path.parent().unwrap_or(Path::new(".")))
    }

    /// Parses the JSON form (samples inline).
    pub fn from_json_str(text: &str) -> Result<Self, GapError> {
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let field = if path == "." { "campaign".into() } else { path };
            GapError::field(field, e.into_inner().to_string())
        })
    }

    /// Loads every record's `csv` file into its `samples`.
    fn load_csv_files(&mut self, base_dir: &Path) -> Result<(), GapError> {
        for (ti, test) in self.tests.iter_mut().enumerate() {
            for (si, spec) in test.specimens.iter_mut().enumerate() {
                for (ri, rec) in spec.accelerometers.iter_mut().enumerate() {
                    let field = format!("tests[{ti}].specimens[{si}].accelerometers[{ri}]");
                    let Some(file) = rec.csv.clone() else {
                        continue;
                    };
                    if !rec.samples.is_empty() {
                        return Err(GapError::field(
                            format!("{field}.samples"),
                            "give either `csv` or `samples`, not both",
                        ));
                    }
                    let rel = Path::new(&file);
                    if rel.is_absolute()
                        || rel.components().any(|c| !matches!(c, Component::Normal(_)))
                    {
                        return Err(GapError::field(
                            format!("{field}.csv"),
                            "must be a relative path inside the campaign's folder (no `..`)",
                        ));
                    }
                    let path = base_dir.join(rel);
                    let text = std::fs::read_to_string(&path).map_err(|e| {
                        GapError::field(
                            format!("{field}.csv"),
                            format!("cannot read {}: {e}", path.display()),
                        )
                    })?;
                    let (samples, rows) = accel::parse_csv(&text, &format!("{field}.csv"), &file)?;
                    rec.samples = samples;
                    if let Err(bad) = rec.check_samples() {
                        return Err(GapError::Csv {
                            field: format!("{field}.csv"),
                            file: file.clone(),
                            row: rows.get(bad.index).copied().unwrap_or(rows.len() + 1),
                            column: ACCEL_COLUMNS[bad.column].to_string(),
                            rule: bad.rule,
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Checks everything: format version, ids, each test's config (known, overrides valid,
    /// model builds), durations, resolution, components (body names of the model), masses
    /// (finite, >= 0, of declared components) and accelerometer records (increment in range,
    /// rate, noise, samples). Errors name the field (`tests[i]...`) and, for CSV data, the row.
    pub fn validate(&self, configs_dir: &Path) -> Result<(), GapError> {
        #[cfg(test)]
        crate::models::counts::campaign_validated();
        if self.format_version != FORMAT_VERSION {
            return Err(GapError::field(
                "format_version",
                format!("must be {FORMAT_VERSION}, got {}", self.format_version),
            ));
        }
        if self.name.trim().is_empty() {
            return Err(GapError::field("name", "must not be empty"));
        }
        check_text("name", &self.name, MAX_NAME_CHARS)?;
        check_text("description", &self.description, MAX_TEXT_CHARS)?;
        if let Some(source) = &self.source {
            check_text("source", source, MAX_TEXT_CHARS)?;
        }
        if self.tests.is_empty() {
            return Err(GapError::field(
                "tests",
                "a campaign needs at least one test",
            ));
        }
        let mut ids = BTreeSet::new();
        for (ti, test) in self.tests.iter().enumerate() {
            let f = |rest: &str| format!("tests[{ti}].{rest}");
            if !plain_id(&test.id) {
                return Err(GapError::field(
                    f("id"),
                    "must be 1-64 letters, digits, '-' or '_'",
                ));
            }
            if !ids.insert(test.id.as_str()) {
                return Err(GapError::field(
                    f("id"),
                    format!("`{}` is used twice", test.id),
                ));
            }
            check_text(
                &format!("tests[{ti}].description"),
                &test.description,
                MAX_TEXT_CHARS,
            )?;
            let (_, model) = test.case_model(ti, configs_dir)?;
            let bodies: Vec<(&str, Option<f64>)> = model
                .system
                .bodies
                .iter()
                .map(|b| {
                    let dynamic = matches!(b.kind, crate::physics::body::BodyKind::Dynamic { .. });
                    (b.name.as_str(), dynamic.then_some(b.mass.mass))
                })
                .collect();
            test.validate_measurements(ti, &bodies)?;
        }
        Ok(())
    }

    /// Number of tests, specimens, increments and accelerometer records.
    pub fn counts(&self) -> (usize, usize, usize, usize) {
        let mut out = (self.tests.len(), 0, 0, 0);
        for t in &self.tests {
            out.1 += t.specimens.len();
            for s in &t.specimens {
                out.2 += s.increments.len();
                out.3 += s.accelerometers.len();
            }
        }
        out
    }
}

/// A free-text field: at most `max` characters, no control characters but line breaks and
/// tabs.
fn check_text(field: &str, text: &str, max: usize) -> Result<(), GapError> {
    let chars = text.chars().count();
    if chars > max {
        return Err(GapError::field(
            field,
            format!("has {chars} characters; at most {max}"),
        ));
    }
    if text
        .chars()
        .any(|c| c.is_control() && !matches!(c, '\n' | '\t'))
    {
        return Err(GapError::field(
            field,
            "must not contain control characters",
        ));
    }
    Ok(())
}

/// Moves a case error's field under `tests[i]`.
fn relocate(ti: usize, e: RunError) -> GapError {
    match e {
        RunError::InvalidConfig { field, rule } => {
            GapError::field(format!("tests[{ti}].{field}"), rule)
        }
        other => GapError::field(format!("tests[{ti}].config"), other.to_string()),
    }
}

impl CampaignTest {
    /// The validated case of this test (index `ti` in its campaign, for error paths): the
    /// reference config with `overrides`, `rattle_space` and `drive` applied. The model is
    /// built once to check it.
    pub fn case(&self, ti: usize, configs_dir: &Path) -> Result<CaseSpec, GapError> {
        self.case_model(ti, configs_dir).map(|(case, _)| case)
    }

    /// [`CampaignTest::case`] with the model built to check it.
    fn case_model(
        &self,
        ti: usize,
        configs_dir: &Path,
    ) -> Result<(CaseSpec, BuiltModel), GapError> {
        let f = |rest: &str| format!("tests[{ti}].{rest}");
        if crate::models::reference::reference_config_path(configs_dir, &self.config).is_err() {
            let known = crate::models::reference::reference_config_names(configs_dir);
            return Err(GapError::field(
                f("config"),
                format!(
                    "unknown config `{}` in {} (known: {})",
                    self.config,
                    configs_dir.display(),
                    known.join(", ")
                ),
            ));
        }
        if !self.overrides.is_object() {
            return Err(GapError::field(f("overrides"), "must be a table"));
        }
        let mut adjust_error: Option<GapError> = None;
        let source = crate::cases::CaseSource::Reference(&self.config);
        let overrides = Some(&self.overrides);
        let case = crate::cases::resolve_model(source, overrides, None, configs_dir, |case| {
            if let Err(e) = self.adjust(ti, case, configs_dir) {
                adjust_error = Some(e);
                return Err(RunError::InvalidConfig {
                    field: "adjust".into(),
                    rule: String::new(),
                });
            }
            Ok(())
        });
        match (case, adjust_error) {
            (_, Some(e)) => Err(e),
            (Ok(case), None) => Ok(case),
            (Err(e), None) => Err(relocate(ti, e)),
        }
    }

    /// Applies `rattle_space` and `drive` to the case.
    fn adjust(&self, ti: usize, case: &mut CaseSpec, configs_dir: &Path) -> Result<(), GapError> {
        let f = |rest: &str| format!("tests[{ti}].{rest}");
        if let Some(k) = self.rattle_space {
            let Some(rb) = case.rattle_box.as_mut() else {
                return Err(GapError::field(
                    f("rattle_space"),
                    "sets the tube of a rattle box; give a launcher's measured dimensions in \
                     overrides.launcher.dimensions",
                ));
            };
            if !(k > 0.0 && k <= 1.0) {
                return Err(GapError::field(
                    f("rattle_space"),
                    format!("must lie in (0, 1] (eq. 5.1: item area / enclosure area), got {k}"),
                ));
            }
            rb.tube_inner_side_m = rb.cube_side_m / k.sqrt();
            rb.case = "custom".into();
        }
        let Some(drive) = &self.drive else {
            return Ok(());
        };
        if let Some(p) = &drive.profile {
            case.excitation = crate::models::spec::CaseExcitation::profile(p);
        }
        if drive.level_g.is_none() && drive.frequency_hz.is_none() {
            return Ok(());
        }
        let spec = crate::models::case::resolve_excitation(case, configs_dir)
            .map_err(|e| relocate(ti, e))?;
        let crate::excitation::ExcitationSpec::Sine {
            mut tones,
            settle_s,
            ramp,
        } = spec
        else {
            return Err(GapError::field(
                f("drive"),
                "level_g and frequency_hz set a single-tone sine drive; give other drives in \
                 overrides.excitation",
            ));
        };
        if tones.len() != 1 {
            return Err(GapError::field(
                f("drive"),
                format!(
                    "the drive has {} tones; level_g and frequency_hz need one",
                    tones.len()
                ),
            ));
        }
        if let Some(g) = drive.level_g {
            if !(g.is_finite() && g > 0.0 && g <= 200.0) {
                return Err(GapError::field(
                    f("drive.level_g"),
                    format!("must lie in (0, 200] g (shaker tables reach about 100 g), got {g}"),
                ));
            }
            tones[0].amplitude_g = g;
        }
        if let Some(hz) = drive.frequency_hz {
            let (lo, hi) = (0.1, 5000.0);
            if !(hz.is_finite() && (lo..=hi).contains(&hz)) {
                return Err(GapError::field(
                    f("drive.frequency_hz"),
                    format!(
                        "must lie in [{lo}, {hi}] Hz (the bound of every tone: \
                         cases::bounds), got {hz}"
                    ),
                ));
            }
            tones[0].frequency_hz = hz;
        }
        let spec = crate::excitation::ExcitationSpec::Sine {
            tones,
            settle_s,
            ramp,
        };
        case.excitation = crate::models::spec::CaseExcitation::motion(spec)
            .map_err(|e| GapError::field(f("drive"), e.to_string()))?;
        Ok(())
    }

    /// Checks durations, resolution, components, specimens, masses and records.
    /// `bodies`: the model's body names with the mass of each dynamic one, kg.
    fn validate_measurements(
        &self,
        ti: usize,
        bodies: &[(&str, Option<f64>)],
    ) -> Result<(), GapError> {
        let f = |rest: &str| format!("tests[{ti}].{rest}");
        let d = self.increment_duration_s;
        if !(d.is_finite() && d > 0.0 && d <= MAX_INCREMENT_DURATION_S) {
            return Err(GapError::field(
                f("increment_duration_s"),
                format!("must lie in (0, {MAX_INCREMENT_DURATION_S}] s (30 days), got {d}"),
            ));
        }
        let r = self.scale_resolution_mg;
        if !(r.is_finite() && (MIN_SCALE_RESOLUTION_MG..=1000.0).contains(&r)) {
            return Err(GapError::field(
                f("scale_resolution_mg"),
                format!(
                    "must lie in [{MIN_SCALE_RESOLUTION_MG:e}, 1000] mg (an ultra-microbalance \
                     to a kitchen scale), got {r}"
                ),
            ));
        }
        if self.components.is_empty() {
            return Err(GapError::field(
                f("components"),
                "name at least one weighed body",
            ));
        }
        for (ci, c) in self.components.iter().enumerate() {
            if !bodies.iter().any(|(name, _)| name == c) {
                let names: Vec<&str> = bodies.iter().map(|(name, _)| *name).collect();
                return Err(GapError::field(
                    f(&format!("components[{ci}]")),
                    format!(
                        "`{c}` is not a body of the model (bodies: {})",
                        names.join(", ")
                    ),
                ));
            }
        }
        if self.specimens.is_empty() {
            return Err(GapError::field(
                f("specimens"),
                "a test needs at least one specimen",
            ));
        }
        let mut ids = BTreeSet::new();
        for (si, spec) in self.specimens.iter().enumerate() {
            let fs = |rest: &str| f(&format!("specimens[{si}].{rest}"));
            if !plain_id(&spec.id) {
                return Err(GapError::field(
                    fs("id"),
                    "must be 1-64 letters, digits, '-' or '_'",
                ));
            }
            if !ids.insert(spec.id.as_str()) {
                return Err(GapError::field(
                    fs("id"),
                    format!("`{}` is used twice", spec.id),
                ));
            }
            if spec.increments.is_empty() {
                return Err(GapError::field(fs("increments"), "at least one increment"));
            }
            for (ii, inc) in spec.increments.iter().enumerate() {
                for (comp, mass) in &inc.mass_loss_mg {
                    let field = fs(&format!("increments[{ii}].mass_loss_mg.{comp}"));
                    if !self.components.contains(comp) {
                        return Err(GapError::field(
                            field,
                            format!("`{comp}` is not in the test's components"),
                        ));
                    }
                    if !(mass.is_finite() && *mass >= 0.0) {
                        return Err(GapError::field(
                            field,
                            format!("mass loss must be a finite number >= 0 mg, got {mass}"),
                        ));
                    }
                    let own_mg = bodies
                        .iter()
                        .find(|(name, _)| name == comp)
                        .and_then(|(_, kg)| *kg)
                        .map(|kg| kg * crate::units::MG_PER_KG);
                    let cap = own_mg.map_or(MAX_INCREMENT_MASS_LOSS_MG, |m| {
                        m.min(MAX_INCREMENT_MASS_LOSS_MG)
                    });
                    if *mass > cap {
                        let why = match own_mg {
                            Some(m) if m < MAX_INCREMENT_MASS_LOSS_MG => {
                                format!("the component's own mass in the model, {m:.4e} mg")
                            }
                            _ => {
                                "100 g: wear increments remove micrograms to milligrams".to_string()
                            }
                        };
                        return Err(GapError::field(
                            field,
                            format!("mass loss {mass} mg exceeds {why}"),
                        ));
                    }
                }
            }
            for (ri, rec) in spec.accelerometers.iter().enumerate() {
                let fr = |rest: &str| fs(&format!("accelerometers[{ri}].{rest}"));
                if rec.increment < 1 || rec.increment > spec.increments.len() {
                    return Err(GapError::field(
                        fr("increment"),
                        format!(
                            "must lie in 1..={} (the specimen's increments), got {}",
                            spec.increments.len(),
                            rec.increment
                        ),
                    ));
                }
                if !(rec.sample_rate_hz.is_finite()
                    && rec.sample_rate_hz > 0.0
                    && rec.sample_rate_hz <= MAX_ACCEL_SAMPLE_RATE_HZ)
                {
                    return Err(GapError::field(
                        fr("sample_rate_hz"),
                        format!(
                            "must lie in (0, {MAX_ACCEL_SAMPLE_RATE_HZ:e}] Hz (past any \
                             vibration accelerometer's band)"
                        ),
                    ));
                }
                if !(rec.sensor_noise_m_s2.is_finite()
                    && rec.sensor_noise_m_s2 >= 0.0
                    && rec.sensor_noise_m_s2 <= MAX_SENSOR_NOISE_M_S2)
                {
                    return Err(GapError::field(
                        fr("sensor_noise_m_s2"),
                        format!(
                            "must lie in [0, {MAX_SENSOR_NOISE_M_S2:e}] m/s² (more noise buries \
                             any captive-carry signal)"
                        ),
                    ));
                }
                if let Err(bad) = rec.check_samples() {
                    let column = ACCEL_COLUMNS[bad.column];
                    return Err(GapError::field(
                        fr(&format!("samples[{}]", bad.index)),
                        format!("{column}: {}", bad.rule),
                    ));
                }
                for (i, sample) in rec.samples.iter().enumerate() {
                    if let Some(j) = (1..4).find(|&j| sample[j].abs() > MAX_ACCELERATION_M_S2) {
                        return Err(GapError::field(
                            fr(&format!("samples[{i}]")),
                            format!(
                                "{}: |{}| m/s² exceeds {MAX_ACCELERATION_M_S2:e} m/s² (about \
                                 1000 g: a unit error or a shock, not captive-carry vibration)",
                                ACCEL_COLUMNS[j], sample[j]
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Rattle space of the test's case (eq. 5.1-5.2 or 6.1-6.3), when the model has one.
    pub fn rattle_space_of(case: &CaseSpec) -> Option<f64> {
        match case.model_spec() {
            Ok(ModelSpecRef::RattleBox(s)) => s.rattle_space().ok(),
            Ok(ModelSpecRef::Launcher(s)) => s.rattle_space().ok(),
            _ => None,
        }
    }
}
