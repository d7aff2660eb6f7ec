//! The tests a next test is chosen from: what the campaign's cases and the reference configs
//! allow, a small deterministic set.
//!
//! A **setup** is what must be simulated: a case (each distinct case of the campaign, then each
//! reference config of the same model the campaign does not use, at most [`MAX_CASES`]) under
//! a drive (the case's own; its single tone at 1.5 times the level; the tone moved to each of
//! the two other axes), at most [`MAX_SETUPS`]. A **schedule** is how a setup is run and read,
//! and costs no simulation: the campaign's increment length, one increment or the campaign's
//! most, one specimen or three, input and response accelerometer records off or on.

use crate::excitation::{Axis, ExcitationSpec, Tone};
use crate::gap::campaign::{Campaign, CampaignTest, DriveSpec, Increment, Specimen};
use crate::models::spec::CaseSpec;
use std::path::Path;

/// Cases tried: the campaign's own and the reference configs of its model beside them.
pub const MAX_CASES: usize = 6;

/// Setups simulated (case and drive): with up to five candidates each, at most 80 test
/// simulations of the campaign's increments (one window each when no effect depends on test
/// time or slip).
pub const MAX_SETUPS: usize = 16;

/// Repeats a schedule may ask for: one specimen, or three (a constant factor is told from
/// specimen scatter by repeats, not by increments; module `separation`).
pub const REPEATS: [usize; 2] = [1, 3];

/// Level factor of the louder drive (capped at a shaker table's 200 g).
pub const LOUDER: f64 = 1.5;

/// One case under one drive, as a campaign test without specimens.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// The test entry (specimens empty).
    pub template: CampaignTest,
    /// The case in words (`rattle-box-b, rattle space 0.44`).
    pub case: String,
    /// What it changes from the campaign, in words.
    pub change: String,
    /// Axis of the drive tone (`x`, `y`, `z`), when it is a single tone.
    pub drive_axis: Option<String>,
    /// Peak level of the tone, g.
    pub level_g: Option<f64>,
    /// Frequency of the tone, Hz.
    pub frequency_hz: Option<f64>,
}

/// How a setup is run and read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// Increments per specimen.
    pub increments: usize,
    /// Excited duration of each, s.
    pub increment_duration_s: f64,
    /// Specimens.
    pub repeats: usize,
    /// Input and response accelerometer records.
    pub accelerometers: bool,
}

impl Schedule {
    /// Test hours: increments x length x repeats.
    pub fn cost_h(&self) -> f64 {
        self.increments as f64 * self.increment_duration_s / crate::units::S_PER_H
            * self.repeats as f64
    }
}

/// The candidate setups of `campaign` (module documentation), in a fixed order: every case
/// as it is, then louder, then on the other axes.
pub fn setups(campaign: &Campaign, configs_dir: &Path) -> Vec<Setup> {
    let Some(model) = campaign
        .tests
        .first()
        .and_then(|t| t.case(0, configs_dir).ok())
        .map(|c| c.model)
    else {
        return Vec::new();
    };
    let mut cases: Vec<(CampaignTest, CaseSpec, String)> = Vec::new();
    let mut seen: Vec<String> = Vec::new();
    for t in &campaign.tests {
        let key = case_key(t);
        if seen.contains(&key) {
            continue;
        }
        if let Ok(case) = t.case(0, configs_dir) {
            seen.push(key);
            cases.push((bare(t), case, format!("as test {}", t.id)));
        }
    }
    let first_drive = campaign.tests.first().and_then(|t| t.drive.clone());
    for config in crate::models::reference::reference_config_names(configs_dir) {
        if campaign.tests.iter().any(|t| t.config == config) {
            continue;
        }
        let template = CampaignTest {
            config: config.clone(),
            drive: first_drive.clone(),
            ..bare(&campaign.tests[0])
        };
        let template = CampaignTest {
            overrides: serde_json::json!({}),
            rattle_space: None,
            ..template
        };
        if let Ok(case) = template.case(0, configs_dir) {
            if case.model == model {
                cases.push((
                    template,
                    case,
                    format!("{config}, a case the campaign lacks"),
                ));
            }
        }
    }
    cases.truncate(MAX_CASES);
    // Variants by kind across cases, so the cap keeps every case as it is first.
    let mut out: Vec<(usize, Setup)> = Vec::new();
    for (template, case, change) in &cases {
        let label = case_label(template, case);
        let tone = single_tone(case, configs_dir);
        out.push((
            0,
            setup(template.clone(), &label, change.clone(), tone.as_ref()),
        ));
        let Some((tone, settle_s, ramp)) = tone else {
            continue;
        };
        let level = (LOUDER * tone.amplitude_g).min(200.0);
        if level > tone.amplitude_g {
            let louder = CampaignTest {
                drive: Some(DriveSpec {
                    profile: template.drive.as_ref().and_then(|d| d.profile.clone()),
                    level_g: Some(level),
                    frequency_hz: Some(tone.frequency_hz),
                }),
                ..template.clone()
            };
            let t = Tone {
                amplitude_g: level,
                ..tone
            };
            let change = format!("{change}, drive {level:.1} g");
            out.push((1, setup(louder, &label, change, Some(&(t, settle_s, ramp)))));
        }
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            if axis == tone.axis {
                continue;
            }
            let t = Tone { axis, ..tone };
            let spec = ExcitationSpec::Sine {
                tones: vec![t],
                settle_s,
                ramp,
            };
            let Ok(excitation) = serde_json::to_value(&spec) else {
                continue;
            };
            let mut overrides = template.overrides.clone();
            if let Some(map) = overrides.as_object_mut() {
                map.insert("excitation".into(), excitation);
            }
            let moved = CampaignTest {
                overrides,
                drive: None,
                ..template.clone()
            };
            let change = format!("{change}, drive on {}", axis_name(axis));
            out.push((2, setup(moved, &label, change, Some(&(t, settle_s, ramp)))));
        }
    }
    out.sort_by_key(|(kind, _)| *kind);
    out.into_iter().map(|(_, s)| s).take(MAX_SETUPS).collect()
}

/// Campaign test `id` as it was run: its case and drive as a setup, and its schedule (its
/// increments, their length, its specimens up to the most [`REPEATS`] allows, its records).
/// None when no test has that id or its case does not read.
pub fn repeat_of(campaign: &Campaign, id: &str, configs_dir: &Path) -> Option<(Setup, Schedule)> {
    let t = campaign.tests.iter().find(|t| t.id == id)?;
    let case = t.case(0, configs_dir).ok()?;
    let label = case_label(t, &case);
    let tone = single_tone(&case, configs_dir);
    let most_repeats = REPEATS.iter().copied().max().unwrap_or(1);
    let schedule = Schedule {
        increments: t
            .specimens
            .iter()
            .map(|s| s.increments.len())
            .max()
            .unwrap_or(1)
            .max(1),
        increment_duration_s: t.increment_duration_s,
        repeats: t.specimens.len().clamp(1, most_repeats),
        accelerometers: t.specimens.iter().any(|s| !s.accelerometers.is_empty()),
    };
    let change = format!("a repeat of test {id} as it was run");
    Some((setup(bare(t), &label, change, tone.as_ref()), schedule))
}

/// The schedules every setup is read under: the campaign's longest increment, one increment
/// or the campaign's most, [`REPEATS`], records off or on.
pub fn schedules(campaign: &Campaign) -> Vec<Schedule> {
    let most = campaign
        .tests
        .iter()
        .flat_map(|t| t.specimens.iter().map(|s| s.increments.len()))
        .max()
        .unwrap_or(1)
        .max(1);
    let length = campaign
        .tests
        .iter()
        .map(|t| t.increment_duration_s)
        .fold(0.0, f64::max);
    let mut counts = vec![1];
    if most > 1 {
        counts.push(most);
    }
    let mut out = Vec::new();
    for &increments in &counts {
        for repeats in REPEATS {
            for accelerometers in [false, true] {
                out.push(Schedule {
                    increments,
                    increment_duration_s: length,
                    repeats,
                    accelerometers,
                });
            }
        }
    }
    out
}

/// The test entry a rig can run and a campaign can append: `setup` under `schedule`, its
/// specimens with empty increments (a skeleton, as `railwear rig` fills).
pub fn test_entry(
    setup: &Setup,
    schedule: &Schedule,
    id: &str,
    components: &[String],
    resolution_mg: f64,
    description: String,
) -> CampaignTest {
    CampaignTest {
        id: id.to_string(),
        description,
        increment_duration_s: schedule.increment_duration_s,
        scale_resolution_mg: resolution_mg,
        components: components.to_vec(),
        specimens: (1..=schedule.repeats)
            .map(|j| Specimen {
                id: format!("{id}-{j}"),
                increments: vec![Increment::default(); schedule.increments],
                accelerometers: Vec::new(),
            })
            .collect(),
        ..setup.template.clone()
    }
}

fn setup(
    template: CampaignTest,
    case: &str,
    change: String,
    tone: Option<&(Tone, f64, crate::excitation::RampSpec)>,
) -> Setup {
    Setup {
        template,
        case: case.to_string(),
        change,
        drive_axis: tone.map(|(t, _, _)| axis_name(t.axis).to_string()),
        level_g: tone.map(|(t, _, _)| t.amplitude_g),
        frequency_hz: tone.map(|(t, _, _)| t.frequency_hz),
    }
}

/// Whether `setup` is campaign test `t`'s case under `t`'s drive (then it is a repeat of `t`,
/// whatever its schedule).
pub fn same_case(setup: &Setup, t: &CampaignTest) -> bool {
    case_key(&setup.template) == case_key(t)
}

/// The test's configuration without its measurements.
fn bare(t: &CampaignTest) -> CampaignTest {
    CampaignTest {
        id: String::new(),
        description: String::new(),
        specimens: Vec::new(),
        ..t.clone()
    }
}

/// What makes two tests the same case: config, overrides, rattle space and drive.
fn case_key(t: &CampaignTest) -> String {
    serde_json::json!([t.config, t.overrides, t.rattle_space, t.drive]).to_string()
}

fn case_label(t: &CampaignTest, case: &CaseSpec) -> String {
    match CampaignTest::rattle_space_of(case) {
        Some(k) => format!("{}, rattle space {k:.2}", t.config),
        None => t.config.clone(),
    }
}

/// The case's drive when it is one sine tone: the tone, its settle and ramp.
fn single_tone(
    case: &CaseSpec,
    configs_dir: &Path,
) -> Option<(Tone, f64, crate::excitation::RampSpec)> {
    match crate::models::case::resolve_excitation(case, configs_dir).ok()? {
        ExcitationSpec::Sine {
            tones,
            settle_s,
            ramp,
        } if tones.len() == 1 => Some((tones[0], settle_s, ramp)),
        _ => None,
    }
}

fn axis_name(a: Axis) -> &'static str {
    match a {
        Axis::X => "x",
        Axis::Y => "y",
        Axis::Z => "z",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configs() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
    }

    /// Two tests; B has four specimens of two one-hour increments at 25 g.
    fn campaign() -> Campaign {
        let specimen =
            |id: &str| format!("[[tests.specimens]]\nid = \"{id}\"\nincrements = [{{}}, {{}}]\n");
        let text = format!(
            "format_version = 1\nname = \"repeat\"\n\
             [[tests]]\nid = \"A\"\nconfig = \"rattle-box-a\"\nincrement_duration_s = 28800.0\n\
             scale_resolution_mg = 0.05\ncomponents = [\"cube\"]\n{}\
             [[tests]]\nid = \"B\"\nconfig = \"rattle-box-b\"\n\
             drive = {{ level_g = 25.0, frequency_hz = 20.0 }}\nincrement_duration_s = 3600.0\n\
             scale_resolution_mg = 0.05\ncomponents = [\"cube\"]\n{}{}{}{}",
            specimen("A-1"),
            specimen("B-1"),
            specimen("B-2"),
            specimen("B-3"),
            specimen("B-4"),
        );
        Campaign::from_toml_str(&text, Path::new(".")).unwrap()
    }

    #[test]
    fn a_repeat_is_the_test_as_it_was_run() {
        let c = campaign();
        let (setup, schedule) = repeat_of(&c, "B", &configs()).unwrap();
        assert_eq!(setup.template.config, "rattle-box-b");
        assert_eq!(setup.template.drive, c.tests[1].drive);
        assert!(setup.template.specimens.is_empty());
        assert_eq!(setup.level_g, Some(25.0));
        assert_eq!(schedule.increments, 2);
        assert_eq!(schedule.increment_duration_s, 3600.0);
        // Four specimens were run; a repeat asks for at most three.
        assert_eq!(schedule.repeats, 3);
        assert!(!schedule.accelerometers);
        assert_eq!(schedule.cost_h(), 6.0);
        assert!(repeat_of(&c, "Z", &configs()).is_none());
    }
}
