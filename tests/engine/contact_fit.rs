//! `railwear contact-fit` (issue 30 item 4): the Hertz fit returns the closed form of eq. 2.10,
//! the range and weighting are stated, and a bad value exits non-zero naming its flag.

use std::process::{Command, Output};

fn contact_fit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_railwear"))
        .arg("contact-fit")
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .expect("railwear runs")
}

#[test]
fn hertz_fit_of_steel_is_the_closed_form() {
    // Steel sphere, R = 10 mm, on a steel flat: E 210 GPa, nu 0.3.
    let out = contact_fit(&[
        "--model",
        "hertz",
        "--radius-m",
        "0.01",
        "--youngs-modulus-pa",
        "210e9",
        "--poisson-ratio",
        "0.3",
        "--yield-strength-pa",
        "250e6",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fit: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    // F = 4/3 E* sqrt(R) w^1.5 with E* = E / (2 (1 - nu²)).
    let e_star = 210e9 / (2.0 * (1.0 - 0.3 * 0.3));
    let k = 4.0 / 3.0 * e_star * 0.01f64.sqrt();
    let got_k = fit["stiffness_si"].as_f64().unwrap();
    let got_e = fit["exponent"].as_f64().unwrap();
    assert!((got_e - 1.5).abs() < 1e-9, "{got_e}");
    assert!((got_k - k).abs() / k < 1e-8, "{got_k} vs {k}");
    // The range and weighting travel with the numbers: 400 uniform samples over (0, 1 mm].
    assert_eq!(fit["range"]["max_interference_m"].as_f64(), Some(1e-3));
    assert_eq!(fit["range"]["samples"].as_u64(), Some(400));
    assert!(fit["weighting"].as_str().unwrap().contains("force"));
}

#[test]
fn the_summary_states_range_and_weighting() {
    let out = contact_fit(&["--model", "kogut-etsion", "--fit-space", "log"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Kogut-Etsion"), "{text}");
    // Log-spaced from 1 mm / 1000.
    assert!(
        text.contains("w from 0.001000 mm to 1 mm, 400 samples log-spaced"),
        "{text}"
    );
    assert!(text.contains("weighting: least squares on ln F"), "{text}");
}

#[test]
fn a_bad_value_exits_non_zero_naming_its_flag() {
    for (args, flag, rule) in [
        (
            vec!["--model", "hertz", "--radius-m", "-0.01"],
            "--radius-m",
            "> 0",
        ),
        (
            vec!["--model", "hertz", "--flat-poisson-ratio", "0.7"],
            "--flat-poisson-ratio",
            "(-1, 0.5)",
        ),
        (
            vec!["--model", "hertz", "--samples", "2"],
            "--samples",
            "3..=",
        ),
        (vec!["--model", "greenwood"], "--model", "kogut_etsion"),
        (
            vec!["--model", "hertz", "--fit-space", "cubic"],
            "--fit-space",
            "log",
        ),
    ] {
        let out = contact_fit(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(err.contains(rule), "{args:?}: {err}");
    }
}
