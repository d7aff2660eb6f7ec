//! Issue 17: a run stopped with a checkpoint and resumed from its bytes, in a fresh build of
//! the model, gives the uninterrupted run's result bit for bit (summary JSON text, tracks CSV,
//! plots), and the energy account still closes. Checked on rattle box C (one system) and on
//! the launcher, interrupted at several steps (before the first step, in the settle, in the
//! excited window, twice in a row). A checkpoint of another case, code version or format is
//! not resumed: the run restarts from t = 0 (and gives that case's own result).
//!
//! With a record sink the run hands its growing records over in chunks as it goes, and a
//! checkpoint carries only the state and the records since the last chunk: on a run long enough
//! for many chunks, the checkpoint at 80 % is no larger than twice the one at 20 % (without a
//! sink it grows with the run), and resumed with its chunks the run still ends bit for bit as
//! the uninterrupted one; with chunks missing or altered the checkpoint is refused.

use railwear::models::case::{build, code_version, load_case};
use railwear::models::checkpoint::{self, CheckpointError, RunIdentity};
use railwear::models::spec::CaseSpec;
use railwear::physics::energy::ENERGY_BALANCE_TOLERANCE;
use railwear::physics::track::TrackSample;
use railwear::pipeline::{
    run_case_from, Progress, RecordChunk, RecordSink, RunControl, RunError, SavedRun,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Duration;

fn configs() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs")
}

fn short_case(file: &str, settle_s: f64, duration_s: f64) -> CaseSpec {
    let mut case = load_case(&configs().join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    case.simulation.settle_s = settle_s;
    case.simulation.duration_s = duration_s;
    case
}

/// What must not change: the summary JSON text, the tracks CSV and the plots.
#[derive(Debug, PartialEq)]
struct Results {
    summary: String,
    tracks_csv: String,
    plots: Vec<(String, String)>,
}

fn csv(tracks: &[TrackSample]) -> String {
    let mut out = Vec::new();
    TrackSample::write_csv(tracks, &mut out).expect("writing to memory");
    String::from_utf8(out).expect("the track CSV is ASCII")
}

/// A control that asks for a checkpoint at the first accepted step at or past simulated time
/// `at_s` (0: before the first step). Progress is reported after every accepted step, so the
/// checkpoint falls on the same step in every run, whatever the machine's speed.
fn checkpoint_at(at_s: f64) -> RunControl {
    let control = RunControl::silent();
    let (c, k) = (control.cancel.clone(), control.checkpoint.clone());
    let control = RunControl {
        progress: Arc::new(move |p: Progress| {
            if p.simulated_time_s >= at_s {
                k.store(true, Ordering::SeqCst);
                c.store(true, Ordering::SeqCst);
            }
        }),
        progress_interval: Duration::ZERO,
        ..control
    };
    if at_s <= 0.0 {
        control.request_checkpoint();
    }
    control
}

/// A control that asks for a checkpoint at the first accepted step past `fraction` of the run
/// (for a model run part by part, the fraction counts the finished parts).
fn checkpoint_past(fraction: f64) -> RunControl {
    let control = RunControl::silent();
    let (c, k) = (control.cancel.clone(), control.checkpoint.clone());
    RunControl {
        progress: Arc::new(move |p: Progress| {
            if p.fraction > fraction {
                k.store(true, Ordering::SeqCst);
                c.store(true, Ordering::SeqCst);
            }
        }),
        progress_interval: Duration::ZERO,
        ..control
    }
}

/// Runs `case` to the end from `resume`; the results, the energy account's closure and the
/// time the run resumed from.
fn finish(case: &CaseSpec, resume: Option<&[u8]>) -> (Results, Option<f64>) {
    finish_saved(case, resume.map(SavedRun::without_chunks))
}

/// [`finish`] from a checkpoint with its record chunks.
fn finish_saved(case: &CaseSpec, resume: Option<SavedRun<'_>>) -> (Results, Option<f64>) {
    let started = std::time::Instant::now();
    let (report, outcome) = run_case_from(case, &configs(), &RunControl::silent(), resume)
        .unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let energy = report.energy.as_ref().expect("energy account");
    let throughput =
        (energy.drive_work_j.abs() + energy.applied_work_j.abs()).max(energy.dissipated_j);
    assert!(
        energy.balanced && energy.residual_j.abs() <= ENERGY_BALANCE_TOLERANCE * throughput + 1e-9,
        "{}: the energy account does not close: {energy:?}",
        case.name
    );
    assert!(energy.dissipated_j > 0.0, "the contacts dissipated nothing");
    eprintln!(
        "{}: run from {:?} s took {:.2} s",
        case.name,
        report.resumed_from_s,
        started.elapsed().as_secs_f64()
    );
    (
        Results {
            summary: serde_json::to_string(&outcome.summary).expect("summary"),
            tracks_csv: csv(&outcome.tracks),
            plots: outcome.plots,
        },
        report.resumed_from_s,
    )
}

/// Runs `case` from `resume` until the checkpoint `control` asks for; its bytes and time.
fn stop(case: &CaseSpec, resume: Option<&[u8]>, control: &RunControl) -> (Vec<u8>, f64) {
    stop_saved(case, resume.map(SavedRun::without_chunks), control)
}

/// [`stop`] from a checkpoint with its record chunks.
fn stop_saved(
    case: &CaseSpec,
    resume: Option<SavedRun<'_>>,
    control: &RunControl,
) -> (Vec<u8>, f64) {
    match run_case_from(case, &configs(), control, resume) {
        Err(RunError::Checkpointed(cp)) => {
            let end = case.simulation.settle_s + case.simulation.duration_s;
            assert_eq!(cp.end_time_s, end);
            assert!(
                (0.0..end).contains(&cp.simulated_time_s),
                "checkpoint at {} s",
                cp.simulated_time_s
            );
            eprintln!(
                "{}: checkpoint at {} s, {} bytes",
                case.name,
                cp.simulated_time_s,
                cp.bytes.len()
            );
            (cp.bytes.clone(), cp.simulated_time_s)
        }
        Ok(_) => panic!(
            "{}: the run ended before the checkpoint was asked for",
            case.name
        ),
        Err(e) => panic!("{}: {e}", case.name),
    }
}

/// Interrupts `case` at the given simulated times, one after the other (each resumed from
/// the previous checkpoint's bytes), then resumes to the end; also resumes each checkpoint
/// directly to the end. Every result must equal the uninterrupted one.
fn check_case(case: &CaseSpec, stops: &[f64]) -> Vec<f64> {
    let (expected, resumed) = finish(case, None);
    assert_eq!(resumed, None);
    let mut resume: Option<Vec<u8>> = None;
    let mut times = Vec::new();
    let mut checkpoints = Vec::new();
    for &at in stops {
        let (bytes, t) = stop(case, resume.as_deref(), &checkpoint_at(at));
        if let Some(&prev) = times.last() {
            assert!(t > prev, "checkpoint at {t} s after one at {prev} s");
        }
        times.push(t);
        checkpoints.push(bytes.clone());
        resume = Some(bytes);
    }
    let (chained, resumed) = finish(case, resume.as_deref());
    assert_eq!(resumed, times.last().copied());
    assert_results_equal(&chained, &expected, &case.name);
    // Each checkpoint alone, resumed straight to the end (the first ones are re-read).
    for (bytes, t) in checkpoints.iter().zip(&times).take(checkpoints.len() - 1) {
        let (direct, resumed) = finish(case, Some(bytes));
        assert_eq!(resumed, Some(*t));
        assert_results_equal(&direct, &expected, &case.name);
    }
    times
}

fn assert_results_equal(got: &Results, expected: &Results, name: &str) {
    assert!(
        got.summary == expected.summary,
        "{name}: summary differs from the uninterrupted run:\n{}\n---\n{}",
        got.summary,
        expected.summary
    );
    assert!(
        got.tracks_csv == expected.tracks_csv,
        "{name}: tracks CSV differs ({} vs {} bytes)",
        got.tracks_csv.len(),
        expected.tracks_csv.len()
    );
    assert!(
        expected.tracks_csv.lines().count() > 10,
        "{name}: too few track samples"
    );
    assert_eq!(got.plots, expected.plots, "{name}: plots differ");
    // Each figure (wear versus time, pressure PDFs, PSD) keeps its text inside its picture.
    for (plot, svg) in &expected.plots {
        let outside = railwear_testkit::svg::texts_outside_view_box(svg);
        assert!(outside.is_empty(), "{name}: {plot}: {outside:#?}");
    }
}

#[test]
fn rattle_box_c_resumes_bit_identically_from_checkpoints_at_several_steps() {
    // Settle 0.05 s, excited 0.25 s: the checkpoints fall before the first step, in the settle
    // or the excited window as the wall clock has it, and twice more later on.
    let case = short_case("rattle-box-c.toml", 0.05, 0.25);
    let times = check_case(&case, &[0.0, 0.04, 0.12, 0.27]);
    assert_eq!(times[0], 0.0, "asked before the first step");
    assert!(times[1] > 0.0);
}

#[test]
fn the_launcher_resumes_bit_identically_from_checkpoints() {
    let case = short_case("launcher-design.toml", 0.05, 0.4);
    let times = check_case(&case, &[0.1, 0.3]);
    assert!(times[0] > 0.0);
}

#[test]
fn a_checkpoint_of_another_case_code_version_or_format_restarts_from_zero() {
    let dir = configs();
    let case = short_case("rattle-box-c.toml", 0.02, 0.4);
    let (bytes, t) = stop(&case, None, &checkpoint_at(0.1));
    assert!(t > 0.0);
    let model = build(&case, &dir).expect("model");
    let identity = RunIdentity::of(&case, &model, &dir);
    assert_eq!(identity.code_version, code_version());
    let decoded = checkpoint::decode(&bytes, &identity, &[]).expect("its own checkpoint decodes");
    assert_eq!(decoded.time_s(), t);

    // Another case: another seed of the same model.
    let mut other = case.clone();
    other.simulation.seed += 1;
    let other_model = build(&other, &dir).expect("model");
    let other_identity = RunIdentity::of(&other, &other_model, &dir);
    assert_ne!(other_identity.case_sha256, identity.case_sha256);
    assert!(matches!(
        checkpoint::decode(&bytes, &other_identity, &[]),
        Err(CheckpointError::Case { .. })
    ));
    let (expected_other, _) = finish(&other, None);
    let (got_other, resumed) = finish(&other, Some(&bytes));
    assert_eq!(resumed, None, "another case's checkpoint was resumed");
    assert_results_equal(&got_other, &expected_other, "other seed");

    // Another code version.
    let foreign = checkpoint::encode(
        &RunIdentity {
            code_version: format!("{}-other", code_version()),
            ..identity.clone()
        },
        &decoded,
    )
    .expect("encode");
    assert!(matches!(
        checkpoint::decode(&foreign.bytes, &identity, &[]),
        Err(CheckpointError::CodeVersion { .. })
    ));
    let (expected, _) = finish(&case, None);
    let (got, resumed) = finish(&case, Some(&foreign.bytes));
    assert_eq!(
        resumed, None,
        "another code version's checkpoint was resumed"
    );
    assert_results_equal(&got, &expected, "code version");

    // Another format (the version leads the stream) and garbage.
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut z, &(checkpoint::CHECKPOINT_FORMAT + 1).to_le_bytes()).unwrap();
    let other_format = z.finish().unwrap();
    assert!(matches!(
        checkpoint::decode(&other_format, &identity, &[]),
        Err(CheckpointError::Format { .. })
    ));
    let (got, resumed) = finish(&case, Some(&other_format));
    assert_eq!(resumed, None);
    assert_results_equal(&got, &expected, "format");
    let (got, resumed) = finish(&case, Some(b"not a checkpoint"));
    assert_eq!(resumed, None);
    assert_results_equal(&got, &expected, "garbage");

    // The checkpoint itself still resumes.
    let (got, resumed) = finish(&case, Some(&bytes));
    assert_eq!(resumed, Some(t));
    assert_results_equal(&got, &expected, "own checkpoint");
}

#[test]
fn the_checkpoint_bytes_round_trip() {
    let dir = configs();
    let case = short_case("rattle-box-c.toml", 0.02, 0.4);
    let (bytes, _) = stop(&case, None, &checkpoint_at(0.1));
    let model = build(&case, Path::new(&dir)).expect("model");
    let identity = RunIdentity::of(&case, &model, &dir);
    let decoded = checkpoint::decode(&bytes, &identity, &[]).expect("decode");
    let again = checkpoint::encode(&identity, &decoded).expect("encode");
    assert_eq!(
        again.bytes, bytes,
        "decode then encode gives the same bytes"
    );
}

#[test]
fn a_launcher_run_part_by_part_resumes_bit_identically_in_either_part() {
    // Two missiles on their own rails: two independent parts, integrated one after the other.
    let dir = configs();
    let case = short_case("launcher-m299-2.toml", 0.05, 0.25);
    let model = build(&case, &dir).expect("model");
    assert_eq!(
        railwear::physics::partition::independent_parts(&model.system).len(),
        2
    );
    let identity = RunIdentity::of(&case, &model, &dir);
    let (expected, _) = finish(&case, None);
    // In the first part, then (resumed from it) in the second.
    let (first, t1) = stop(&case, None, &checkpoint_past(0.2));
    let cp = checkpoint::decode(&first, &identity, &[]).expect("decode");
    assert_eq!(cp.finished_parts(), 0);
    let (second, t2) = stop(&case, Some(&first), &checkpoint_past(0.6));
    let cp = checkpoint::decode(&second, &identity, &[]).expect("decode");
    assert_eq!(
        cp.finished_parts(),
        1,
        "the second checkpoint falls in the second part"
    );
    assert!(t1 > 0.0 && t2 > 0.0);
    for (bytes, t) in [(&first, t1), (&second, t2)] {
        let (got, resumed) = finish(&case, Some(bytes));
        assert_eq!(resumed, Some(t));
        assert_results_equal(&got, &expected, "launcher-m299-2");
    }
}

/// The record chunks a run hands to its sink, kept by number as a store keeps them (a chunk
/// written again replaces the one of its number).
#[derive(Clone)]
struct Chunks {
    kept: Arc<Mutex<Vec<Vec<u8>>>>,
    samples: usize,
}

impl Chunks {
    /// Chunks of `samples` samples each.
    fn of(samples: usize) -> Self {
        Self {
            kept: Arc::default(),
            samples,
        }
    }

    /// `control` with its records handed here.
    fn sink_of(&self, control: RunControl) -> RunControl {
        let kept = self.kept.clone();
        RunControl {
            record_sink: Some(RecordSink {
                chunk_samples: self.samples,
                write: Arc::new(move |chunk: RecordChunk| {
                    let mut kept = kept.lock().expect("chunks");
                    let seq = chunk.seq as usize;
                    assert!(seq <= kept.len(), "chunk {seq} after {} chunks", kept.len());
                    kept.truncate(seq);
                    kept.push(chunk.bytes);
                }),
            }),
            ..control
        }
    }

    fn taken(&self) -> Vec<Vec<u8>> {
        self.kept.lock().expect("chunks").clone()
    }
}

#[test]
fn with_a_record_sink_the_checkpoint_stays_small_and_the_run_resumes_bit_identically() {
    // Rattle box C recording about every accepted step, chunks of 1024 samples: many chunks
    // in a short run.
    let dir = configs();
    let mut case = short_case("rattle-box-c.toml", 0.02, 1.5);
    case.simulation.record_interval_s = 1e-5;
    let end = case.simulation.settle_s + case.simulation.duration_s;
    let (expected, _) = finish(&case, None);
    let model = build(&case, &dir).expect("model");
    let identity = RunIdentity::of(&case, &model, &dir);

    let chunks = Chunks::of(1024);
    let (early, t_early) = stop_saved(&case, None, &chunks.sink_of(checkpoint_at(0.2 * end)));
    let early_chunks = chunks.taken();
    let (late, t_late) = stop_saved(
        &case,
        Some(SavedRun {
            checkpoint: &early,
            record_chunks: &early_chunks,
        }),
        &chunks.sink_of(checkpoint_at(0.8 * end)),
    );
    let late_chunks = chunks.taken();
    let late_cp = checkpoint::decode(&late, &identity, &late_chunks).expect("decode");
    let largest_chunk = late_chunks.iter().map(Vec::len).max().unwrap_or(0);
    eprintln!(
        "checkpoints with a record sink: {} bytes at {t_early} s, {} bytes at {t_late} s; \
         {} chunks, the largest {largest_chunk} bytes",
        early.len(),
        late.len(),
        late_chunks.len()
    );
    assert_eq!(late_cp.record_chunks() as usize, late_chunks.len());
    assert!(
        late_chunks.len() >= 3 * early_chunks.len().max(1) && late_chunks.len() >= 8,
        "{} chunks at 20 %, {} at 80 %: too few to show the bound",
        early_chunks.len(),
        late_chunks.len()
    );
    // What a checkpoint carries beyond the run's state (which does not grow) is less than a
    // chunk's worth of each record: the one at 80 % exceeds the one at 20 % by less than
    // two chunks, and is less than twice its size.
    assert!(
        late.len() < early.len() + 2 * largest_chunk,
        "checkpoint at 80 %: {} bytes, at 20 %: {} bytes, chunks up to {largest_chunk} bytes",
        late.len(),
        early.len()
    );
    assert!(late.len() < 2 * early.len());
    // Without a sink the checkpoint carries every record and grows with the run.
    let (whole, _) = stop(&case, None, &checkpoint_at(0.8 * end));
    assert!(
        whole.len() > 2 * late.len(),
        "a checkpoint without chunks ({} bytes) is not larger than one with ({} bytes)",
        whole.len(),
        late.len()
    );

    // Resumed with its chunks (and the later ones the store may hold), bit for bit.
    for (bytes, t, kept) in [
        (&early, t_early, &late_chunks),
        (&late, t_late, &late_chunks),
    ] {
        let (got, resumed) = finish_saved(
            &case,
            Some(SavedRun {
                checkpoint: bytes,
                record_chunks: kept,
            }),
        );
        assert_eq!(resumed, Some(t));
        assert_results_equal(&got, &expected, "rattle box C, recorded every step");
    }

    // Chunks missing or altered: refused, and the run starts over to the same result.
    let mut altered = late_chunks.clone();
    altered[1][10] ^= 1;
    for (kept, what) in [(&late_chunks[..2], "missing"), (&altered[..], "altered")] {
        assert!(
            matches!(
                checkpoint::decode(&late, &identity, kept),
                Err(CheckpointError::Records(_))
            ),
            "{what} chunks were accepted"
        );
        let (got, resumed) = finish_saved(
            &case,
            Some(SavedRun {
                checkpoint: &late,
                record_chunks: kept,
            }),
        );
        assert_eq!(resumed, None, "resumed with {what} chunks");
        assert_results_equal(&got, &expected, what);
    }
}

#[test]
fn a_launcher_run_part_by_part_with_a_record_sink_resumes_bit_identically() {
    // The first part's report goes out as a chunk when it finishes; resumed in the second
    // part, the run takes it back.
    let case = short_case("launcher-m299-2.toml", 0.05, 0.25);
    let (expected, _) = finish(&case, None);
    let chunks = Chunks::of(64);
    let (first, t1) = stop_saved(&case, None, &chunks.sink_of(checkpoint_past(0.2)));
    let first_chunks = chunks.taken();
    let (second, t2) = stop_saved(
        &case,
        Some(SavedRun {
            checkpoint: &first,
            record_chunks: &first_chunks,
        }),
        &chunks.sink_of(checkpoint_past(0.6)),
    );
    let second_chunks = chunks.taken();
    assert!(
        second_chunks.len() > first_chunks.len(),
        "the finished part wrote no chunk"
    );
    for (bytes, t) in [(&first, t1), (&second, t2)] {
        let (got, resumed) = finish_saved(
            &case,
            Some(SavedRun {
                checkpoint: bytes,
                record_chunks: &second_chunks,
            }),
        );
        assert_eq!(resumed, Some(t));
        assert_results_equal(&got, &expected, "launcher-m299-2 with chunks");
    }
}
