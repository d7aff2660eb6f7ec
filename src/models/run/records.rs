//! A run's growing records (track samples, the response velocity, finished parts' reports)
//! written out in chunks as they accumulate, so that a checkpoint carries only what came after
//! the last chunk: its size and write time stay bounded however long the run
//! (docs/reference/operations.md, "Checkpoints and the shutdown grace").
//!
//! With a record sink ([`RunControl::record_sink`](crate::physics::control::RunControl)) the
//! run hands over a chunk whenever the sink's `chunk_samples` track samples or response
//! samples have accumulated, and each part of a model run part by part hands over its report
//! when it finishes. The run keeps everything in memory as
//! before (its report needs it); the chunks are a copy for the checkpoint's sake. A checkpoint
//! records how many chunks preceded it and a chained SHA-256 over their bytes; resuming takes
//! the chunks back, checks the chain and puts the records together again, so the resumed run
//! holds exactly what the uninterrupted one held at that step. Chunk boundaries follow sample
//! counts, not the wall clock, so every run of a case writes the same chunks.

use super::{ModelCheckpoint, RunReport};
use crate::physics::control::{RecordChunk, RecordSink};
use crate::physics::track::TrackSample;
use bincode::Options;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sha2::{Digest, Sha256};

/// Largest chunk decoded, bytes (after decompression): a guard against a corrupt length.
const MAX_DECODED_BYTES: u64 = 4 << 30;

fn codec() -> impl Options {
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .with_little_endian()
        .with_limit(MAX_DECODED_BYTES)
}

/// A response-velocity sample: time, s, and velocity, m/s.
pub(super) type VelocitySample = (f64, [f64; 3]);

/// A record that only grows, whose first `written` items went out in chunks. Serialized as
/// that count and the items after it; read back, the written items are missing until
/// [`Appended::restore`] puts the chunks' items in front.
#[derive(Debug, Clone)]
pub(super) struct Appended<T> {
    items: Vec<T>,
    written: usize,
    missing: usize,
}

impl<T> Default for Appended<T> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            written: 0,
            missing: 0,
        }
    }
}

impl<T: Clone> Appended<T> {
    pub(super) fn push(&mut self, item: T) {
        self.items.push(item);
    }

    /// The items, to append to.
    pub(super) fn items_mut(&mut self) -> &mut Vec<T> {
        &mut self.items
    }

    pub(super) fn len(&self) -> usize {
        self.items.len() + self.missing
    }

    /// The items not yet written out.
    fn unwritten(&self) -> &[T] {
        &self.items[self.written - self.missing..]
    }

    /// True when every item is present (none missing after a decode).
    pub(super) fn complete(&self) -> bool {
        self.missing == 0
    }

    pub(super) fn into_items(self) -> Vec<T> {
        self.items
    }

    /// Puts the items the chunks held in front; they must be exactly the missing ones.
    fn restore(&mut self, mut prefix: Vec<T>, what: &str) -> Result<(), String> {
        if prefix.len() != self.missing {
            return Err(format!(
                "the chunks hold {} {what}, the checkpoint follows {}",
                prefix.len(),
                self.missing
            ));
        }
        prefix.append(&mut self.items);
        self.items = prefix;
        self.missing = 0;
        Ok(())
    }
}

impl<T: Serialize> Serialize for Appended<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let tail = &self.items[self.written - self.missing..];
        (self.written as u64, tail).serialize(s)
    }
}

impl<'de, T: DeserializeOwned> Deserialize<'de> for Appended<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (written, items): (u64, Vec<T>) = Deserialize::deserialize(d)?;
        let written = usize::try_from(written).map_err(serde::de::Error::custom)?;
        Ok(Self {
            items,
            written,
            missing: written,
        })
    }
}

/// How many chunks a run wrote and the chained SHA-256 of their bytes: what a checkpoint needs
/// to take the right chunks back.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub(super) struct RecordMark {
    chunks: u64,
    chain: [u8; 32],
}

impl RecordMark {
    fn next(&self, bytes: &[u8]) -> Self {
        let mut hash = Sha256::new();
        hash.update(self.chain);
        hash.update(bytes);
        Self {
            chunks: self.chunks + 1,
            chain: hash.finalize().into(),
        }
    }

    /// Chunks written before the checkpoint.
    pub(super) fn chunks(&self) -> u64 {
        self.chunks
    }
}

/// One chunk's content.
#[derive(Serialize, Deserialize)]
enum Entry {
    /// Samples appended to part `part`'s records since its previous chunk.
    Samples {
        part: u32,
        tracks: Vec<TrackSample>,
        response_velocity: Vec<VelocitySample>,
    },
    /// Part `part` finished: its report, without the track samples its chunks hold.
    PartFinished { part: u32, report: Box<RunReport> },
}

/// Writes a run's chunks to the record sink and keeps the mark.
pub(super) struct RecordWriter {
    sink: Option<RecordSink>,
    mark: RecordMark,
    /// The part running (0 for a model run whole).
    pub(super) part: u32,
    /// True when the model runs part by part: a finished part writes its last samples.
    pub(super) part_of_several: bool,
}

impl RecordWriter {
    /// A writer to `sink` going on from `mark`.
    pub(super) fn new(sink: Option<RecordSink>, mark: RecordMark) -> Self {
        Self {
            sink,
            mark,
            part: 0,
            part_of_several: false,
        }
    }

    pub(super) fn mark(&self) -> RecordMark {
        self.mark.clone()
    }

    /// True when chunks go anywhere.
    pub(super) fn is_on(&self) -> bool {
        self.sink.is_some()
    }

    fn write(&mut self, entry: &Entry) -> bool {
        let Some(sink) = &self.sink else {
            return false;
        };
        let mut z = ZlibEncoder::new(Vec::new(), Compression::fast());
        let encoded = codec()
            .serialize_into(&mut z, entry)
            .map_err(|e| e.to_string())
            .and_then(|()| z.finish().map_err(|e| e.to_string()));
        match encoded {
            Ok(bytes) => {
                let seq = self.mark.chunks;
                self.mark = self.mark.next(&bytes);
                (sink.write)(RecordChunk { seq, bytes });
                true
            }
            Err(e) => {
                // The samples stay unwritten: the checkpoint carries them.
                tracing::warn!(error = %e, "a record chunk could not be encoded");
                false
            }
        }
    }

    /// Writes the part's unwritten samples as a chunk when either record has a chunk's worth
    /// (or, with `all`, whatever there is).
    pub(super) fn samples(
        &mut self,
        tracks: &mut Appended<TrackSample>,
        response: &mut Appended<VelocitySample>,
        all: bool,
    ) {
        let Some(chunk) = self.sink.as_ref().map(|s| s.chunk_samples.max(1)) else {
            return;
        };
        if !tracks.complete() || !response.complete() {
            return;
        }
        let (t, r) = (tracks.unwritten(), response.unwritten());
        let full = t.len() >= chunk || r.len() >= chunk;
        if !(full || all && !(t.is_empty() && r.is_empty())) {
            return;
        }
        let entry = Entry::Samples {
            part: self.part,
            tracks: t.to_vec(),
            response_velocity: r.to_vec(),
        };
        if self.write(&entry) {
            tracks.written = tracks.items.len();
            response.written = response.items.len();
        }
    }

    /// Appends a finished part's report to `finished`, written out as a chunk (its track
    /// samples are in the part's sample chunks) when every earlier one was.
    pub(super) fn part_finished(
        &mut self,
        finished: &mut Appended<RunReport>,
        mut report: RunReport,
    ) {
        let all_written = finished.complete() && finished.unwritten().is_empty();
        if self.is_on() && all_written {
            let tracks = std::mem::take(&mut report.tracks);
            let entry = Entry::PartFinished {
                part: self.part,
                report: Box::new(report),
            };
            let written = self.write(&entry);
            let Entry::PartFinished { report, .. } = entry else {
                unreachable!("built as a finished part above")
            };
            let mut report = *report;
            report.tracks = tracks;
            finished.push(report);
            if written {
                finished.written = finished.items.len();
            }
            return;
        }
        finished.push(report);
    }
}

/// Puts the records of `cp` together again from the chunks the run wrote before it (`chunks`
/// in order from the first; any after those the checkpoint counts are ignored): the chain of
/// their SHA-256 must match the checkpoint's.
pub(super) fn restore(cp: &mut ModelCheckpoint, chunks: &[Vec<u8>]) -> Result<(), String> {
    let needed = usize::try_from(cp.records.chunks).map_err(|e| e.to_string())?;
    if chunks.len() < needed {
        return Err(format!(
            "{} record chunks stored, the checkpoint follows {needed}",
            chunks.len()
        ));
    }
    let mut mark = RecordMark::default();
    let mut entries = Vec::with_capacity(needed);
    for bytes in &chunks[..needed] {
        mark = mark.next(bytes);
        let entry: Entry = codec()
            .deserialize_from(ZlibDecoder::new(bytes.as_slice()))
            .map_err(|e| format!("record chunk {}: {e}", entries.len()))?;
        entries.push(entry);
    }
    if mark != cp.records {
        return Err("the record chunks are not the ones the checkpoint follows".into());
    }
    // Finished parts written out, in part order, each with its samples' tracks.
    let mut tracks_of: Vec<Vec<TrackSample>> = Vec::new();
    let mut response_of: Vec<Vec<VelocitySample>> = Vec::new();
    let mut reports: Vec<RunReport> = Vec::new();
    for entry in entries {
        match entry {
            Entry::Samples {
                part,
                mut tracks,
                mut response_velocity,
            } => {
                let p = part as usize;
                if tracks_of.len() <= p {
                    tracks_of.resize_with(p + 1, Vec::new);
                    response_of.resize_with(p + 1, Vec::new);
                }
                tracks_of[p].append(&mut tracks);
                response_of[p].append(&mut response_velocity);
            }
            Entry::PartFinished { part, report } => {
                if part as usize != reports.len() {
                    return Err(format!(
                        "part {part} finished after {} parts",
                        reports.len()
                    ));
                }
                reports.push(*report);
            }
        }
    }
    for (p, report) in reports.iter_mut().enumerate() {
        report.tracks = take_part(&mut tracks_of, p);
    }
    cp.finished_parts.restore(reports, "finished parts")?;
    let current = cp.finished_parts.len();
    let tracks = take_part(&mut tracks_of, current);
    let response = take_part(&mut response_of, current);
    let observed = &mut cp.current.observed;
    observed.tracks_out.restore(tracks, "track samples")?;
    observed.resp_vel.restore(response, "response samples")?;
    Ok(())
}

/// Part `part`'s samples gathered from the chunks (none if it has no chunk).
fn take_part<T>(of: &mut [Vec<T>], part: usize) -> Vec<T> {
    of.get_mut(part).map(std::mem::take).unwrap_or_default()
}
