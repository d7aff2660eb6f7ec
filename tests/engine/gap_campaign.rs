//! Campaign format (issue 14 items 1-2): the thesis campaign loads with Table 5.3's numbers,
//! TOML and JSON forms round-trip, and bad campaigns are refused naming the field and row.

use railwear::gap::campaign::{Campaign, CampaignTest};
use railwear::gap::GapError;
use railwear_testkit::TempDir;
use std::path::{Path, PathBuf};
use std::process::Command;

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")
}

fn thesis_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("campaigns/thesis-rattle-box.toml")
}

/// A fresh scratch directory for one test, unique among the tests of this process and
/// removed when the test ends.
fn scratch(name: &str) -> TempDir {
    TempDir::new(&format!("gap-{name}")).expect("scratch dir")
}

/// Thesis Table 5.3, mg/hr per increment as printed.
const TABLE_5_3: [(&str, &[f64]); 4] = [
    ("A", &[21.1333]),
    ("B", &[97.2000]),
    ("C", &[1.5333, 2.2333, 2.3333]),
    ("D", &[0.2666, 0.1666, 0.8666]),
];

#[test]
fn thesis_campaign_loads_with_table_5_3() {
    let c = Campaign::load(&thesis_path()).unwrap();
    c.validate(&configs()).unwrap();
    assert_eq!(c.tests.len(), 4);
    for (test, (id, rates)) in c.tests.iter().zip(TABLE_5_3) {
        assert_eq!(test.id, id);
        // 90 min increments (thesis 5.5), one specimen, the cube weighed (5.3.1).
        assert_eq!(test.increment_duration_s, 90.0 * 60.0);
        assert_eq!(test.components, vec!["cube".to_string()]);
        assert_eq!(test.specimens.len(), 1);
        let incs = &test.specimens[0].increments;
        assert_eq!(incs.len(), rates.len());
        for (inc, rate) in incs.iter().zip(rates) {
            let mass = inc.mass_loss_mg["cube"];
            // A whole number of 0.05 mg scale steps ...
            let steps = mass / test.scale_resolution_mg;
            assert!((steps - steps.round()).abs() < 1e-9, "{id}: {mass}");
            assert_eq!(test.scale_resolution_mg, 0.05);
            // ... whose rate over 1.5 h the thesis printed to 4 decimals (truncated for D).
            let implied = mass / 1.5;
            assert!((implied - rate).abs() < 1.0e-4, "{id}: {implied} vs {rate}");
        }
        // The drive the case gets is 15 g at 20 Hz on x (thesis 5.5).
        let case = test.case(0, &configs()).unwrap();
        let tones = &case.excitation["tones"];
        assert_eq!(tones.as_array().map(Vec::len), Some(1));
        assert_eq!(tones[0]["amplitude_g"].as_f64(), Some(15.0));
        assert_eq!(tones[0]["frequency_hz"].as_f64(), Some(20.0));
        assert_eq!(tones[0]["axis"].as_str(), Some("x"));
    }
    // Table 5.1 rattle spaces through the reference configs.
    let k: Vec<f64> = c
        .tests
        .iter()
        .enumerate()
        .map(|(i, t)| {
            railwear::gap::campaign::CampaignTest::rattle_space_of(&t.case(i, &configs()).unwrap())
                .unwrap()
        })
        .collect();
    for (got, want) in k.iter().zip([0.25, 0.4444, 0.64, 0.7901]) {
        assert!((got - want).abs() < 1e-3, "{got} vs {want}");
    }
}

/// The bench skeletons load and validate against the reference configs, each test's rattle
/// space is eq. 5.1's (item area over enclosure area) for the tube it builds, and no
/// increment carries a measurement (the rig fills them).
#[test]
fn bench_skeletons_load_and_validate() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("campaigns");
    for name in ["bench-rattle-box.toml", "bench-rattle-box-25hz.toml"] {
        let c = Campaign::load(&dir.join(name)).unwrap();
        c.validate(&configs()).unwrap();
        for (ti, test) in c.tests.iter().enumerate() {
            let case = test.case(ti, &configs()).unwrap();
            let rb = case.rattle_box.as_ref().expect("a rattle box");
            let k = (rb.cube_side_m / rb.tube_inner_side_m).powi(2);
            let reported = CampaignTest::rattle_space_of(&case).expect("a rattle space");
            assert!(
                (k - reported).abs() < 1e-12,
                "{name} {}: {k} {reported}",
                test.id
            );
            if let Some(asked) = test.rattle_space {
                assert!((k - asked).abs() < 1e-12, "{name} {}: {k} {asked}", test.id);
            }
            let weighed = test
                .specimens
                .iter()
                .flat_map(|s| &s.increments)
                .any(|i| !i.mass_loss_mg.is_empty());
            assert!(
                !weighed,
                "{name} {}: a skeleton carries no measurement",
                test.id
            );
        }
    }
}

fn with_records() -> Campaign {
    let mut c = Campaign::load(&thesis_path()).unwrap();
    c.tests.truncate(1);
    c.tests[0].specimens[0].accelerometers = vec![railwear::gap::accel::AccelRecord {
        increment: 1,
        location: railwear::gap::accel::AccelLocation::Response,
        sample_rate_hz: 1000.0,
        sensor_noise_m_s2: 0.2,
        csv: None,
        samples: (0..50)
            .map(|i| {
                let t = i as f64 / 1000.0;
                [t, (t * 125.0).sin() * 147.1, 0.1 / 3.0, -1e-9]
            })
            .collect(),
    }];
    c
}

#[test]
fn toml_with_csv_and_json_round_trip() {
    let c = with_records();
    c.validate(&configs()).unwrap();
    let scratch = scratch("roundtrip");
    let dir = scratch.path().to_path_buf();
    c.write_dir(&dir).unwrap();
    let back = Campaign::load(&dir.join("campaign.toml")).unwrap();
    // The manifest names the CSV file; the samples come back bit for bit.
    let rec = &back.tests[0].specimens[0].accelerometers[0];
    assert_eq!(rec.csv.as_deref(), Some("A_A-1_inc1_response.csv"));
    assert_eq!(
        rec.samples,
        c.tests[0].specimens[0].accelerometers[0].samples
    );
    let mut expected = c.clone();
    expected.tests[0].specimens[0].accelerometers[0].csv = rec.csv.clone();
    assert_eq!(back, expected);
    // JSON form: the same content.
    let json = serde_json::to_string(&back).unwrap();
    assert_eq!(Campaign::from_json_str(&json).unwrap(), back);
}

fn field_of(e: &GapError) -> String {
    e.field_path().unwrap_or_default().to_string()
}

#[test]
fn bad_campaigns_name_the_field() {
    let base = std::fs::read_to_string(thesis_path()).unwrap();
    let scratch = scratch("bad");
    let dir = scratch.path().to_path_buf();
    let check = |text: &str| -> GapError {
        match Campaign::from_toml_str(text, &dir) {
            Err(e) => e,
            Ok(c) => c.validate(&configs()).unwrap_err(),
        }
    };
    // Unknown config.
    let e = check(&base.replacen("config = \"rattle-box-b\"", "config = \"rattle-box-q\"", 1));
    assert_eq!(field_of(&e), "tests[1].config");
    assert!(e.to_string().contains("rattle-box-q"), "{e}");
    // Negative mass.
    let e = check(&base.replacen("cube = 3.35", "cube = -3.35", 1));
    assert_eq!(
        field_of(&e),
        "tests[2].specimens[0].increments[1].mass_loss_mg.cube"
    );
    // A component the test does not weigh.
    let e = check(&base.replacen("cube = 3.35", "lid = 3.35", 1));
    assert_eq!(
        field_of(&e),
        "tests[2].specimens[0].increments[1].mass_loss_mg.lid"
    );
    // A component that is not a body of the model.
    let e = check(&base.replacen("components = [\"cube\"]", "components = [\"cub\"]", 1));
    assert_eq!(field_of(&e), "tests[0].components[0]");
    // Unknown key (a typo of a unit-carrying name).
    let e = check(&base.replacen(
        "increment_duration_s = 5400.0",
        "increment_duration_min = 90.0",
        1,
    ));
    assert!(field_of(&e).starts_with("tests[0]"), "{e}");
    assert!(e.to_string().contains("increment_duration_min"), "{e}");
    // A bad override names its path under the test.
    let e = check(&base.replacen(
        "description = \"Case B\"",
        "description = \"Case B\"\noverrides = { rattle_box = { tube_inner_side_m = 0.01 } }",
        1,
    ));
    assert_eq!(
        field_of(&e),
        "tests[1].overrides.rattle_box.tube_inner_side_m"
    );
}

/// A one-test campaign with one accelerometer record read from `csv_text`.
fn record_campaign(dir: &Path, csv_text: Option<&str>) -> String {
    if let Some(text) = csv_text {
        std::fs::write(dir.join("rec.csv"), text).unwrap();
    }
    r#"format_version = 1
name = "records"
[[tests]]
id = "C"
config = "rattle-box-c"
increment_duration_s = 600.0
scale_resolution_mg = 0.01
components = ["cube"]
[[tests.specimens]]
id = "S1"
increments = [{ mass_loss_mg = { cube = 0.5 } }]
[[tests.specimens.accelerometers]]
increment = 1
location = "input"
sample_rate_hz = 100.0
sensor_noise_m_s2 = 0.05
csv = "rec.csv"
"#
    .to_string()
}

fn csv_error(dir: &Path, csv_text: Option<&str>) -> (String, usize, String) {
    let text = record_campaign(dir, csv_text);
    match Campaign::from_toml_str(&text, dir) {
        Err(GapError::Csv {
            field, row, column, ..
        }) => (field, row, column),
        Err(GapError::Field { field, rule }) => (field, 0, rule),
        other => panic!("expected an error, got {other:?}"),
    }
}

#[test]
fn bad_accelerometer_files_name_field_and_row() {
    let scratch = scratch("csv");
    let dir = scratch.path().to_path_buf();
    let field = "tests[0].specimens[0].accelerometers[0].csv";
    let good = "time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2\n0.00,1,0,0\n0.01,2,0,0\n0.02,3,0,0\n";
    let c = Campaign::from_toml_str(&record_campaign(&dir, Some(good)), &dir).unwrap();
    c.validate(&configs()).unwrap();
    assert_eq!(c.tests[0].specimens[0].accelerometers[0].samples.len(), 3);
    // Missing file.
    std::fs::remove_file(dir.join("rec.csv")).unwrap();
    let (f, row, rule) = csv_error(&dir, None);
    assert_eq!((f.as_str(), row), (field, 0));
    assert!(rule.contains("cannot read"), "{rule}");
    // Wrong column: a_y in g instead of m/s².
    let (f, row, col) = csv_error(&dir, Some("time_s,a_x_m_s2,a_y_g,a_z_m_s2\n0,0,0,0\n"));
    assert_eq!((f.as_str(), row, col.as_str()), (field, 1, "a_y_m_s2"));
    // Non-monotonic time at line 4 (the header is line 1, a comment line 2).
    let (f, row, col) = csv_error(
        &dir,
        Some("time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2\n# logger 7\n0.00,1,0,0\n0.00,1,0,0\n"),
    );
    assert_eq!((f.as_str(), row, col.as_str()), (field, 4, "time_s"));
    // Mismatched sample rate: 200 Hz data declared as 100 Hz, caught at the first step.
    let (f, row, _) = csv_error(
        &dir,
        Some("time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2\n0.000,1,0,0\n0.005,1,0,0\n0.010,1,0,0\n"),
    );
    assert_eq!((f.as_str(), row), (field, 3));
    // A dropped sample: rate right at first, a double step at line 5.
    let (_, row, _) = csv_error(
        &dir,
        Some("time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2\n0.00,1,0,0\n0.01,1,0,0\n0.02,1,0,0\n0.04,1,0,0\n"),
    );
    assert_eq!(row, 5);
    // A cell that is not a number.
    let (_, row, col) = csv_error(
        &dir,
        Some("time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2\n0,1,0,0\n0.01,1,x,0\n"),
    );
    assert_eq!((row, col.as_str()), (3, "a_y_m_s2"));
    // A path leaving the campaign's folder.
    let text = record_campaign(&dir, None).replace("csv = \"rec.csv\"", "csv = \"../rec.csv\"");
    let e = Campaign::from_toml_str(&text, &dir).unwrap_err();
    assert_eq!(field_of(&e), field);
}

#[test]
fn json_samples_name_the_sample() {
    let mut c = with_records();
    c.tests[0].specimens[0].accelerometers[0].samples[7][0] = 0.0;
    let json = serde_json::to_string(&c).unwrap();
    let e = Campaign::from_json_str(&json)
        .unwrap()
        .validate(&configs())
        .unwrap_err();
    assert_eq!(
        field_of(&e),
        "tests[0].specimens[0].accelerometers[0].samples[7]"
    );
    assert!(e.to_string().contains("time_s"), "{e}");
}

#[test]
fn cli_check_prints_a_summary_or_the_error() {
    let bin = env!("CARGO_BIN_EXE_railwear");
    let ok = Command::new(bin)
        .args(["campaign", "check"])
        .arg(thesis_path())
        .arg("--configs-dir")
        .arg(configs())
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let out = String::from_utf8_lossy(&ok.stdout);
    assert!(out.contains("4 tests, 4 specimens, 8 increments"), "{out}");
    let scratch = scratch("cli");
    let dir = scratch.path().to_path_buf();
    let bad =
        std::fs::read_to_string(thesis_path())
            .unwrap()
            .replacen("cube = 0.25", "cube = -0.25", 1);
    std::fs::write(dir.join("bad.toml"), bad).unwrap();
    let out = Command::new(bin)
        .args(["campaign", "check"])
        .arg(dir.join("bad.toml"))
        .arg("--configs-dir")
        .arg(configs())
        .env_remove("RUST_BACKTRACE")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("tests[3].specimens[0].increments[1].mass_loss_mg.cube"),
        "{err}"
    );
}
