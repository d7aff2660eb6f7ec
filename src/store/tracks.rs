//! Compact storage of contact tracks: samples are cut into blocks, each block is laid out column
//! by column (all times, then all contact ids, ...; columns of similar numbers compress well) and
//! deflate-compressed. A job with millions of samples is a few hundred rows, not millions.

use crate::physics::track::TrackSample;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use std::io::{Read, Write};

/// Number of f64 columns per sample (everything but contact and track ids).
const F64_COLUMNS: usize = 16;
/// Bytes per sample in the uncompressed block: 16 f64 + 2 u32.
const BYTES_PER_SAMPLE: usize = F64_COLUMNS * 8 + 2 * 4;

/// One encoded block as stored.
#[derive(Debug, Clone, PartialEq, sqlx::FromRow)]
pub struct TrackBlock {
    /// Block index within the job, from 0.
    #[sqlx(rename = "block")]
    pub index: i64,
    /// Samples in the block.
    pub samples: i64,
    /// First and last sample time, s.
    pub t_start_s: f64,
    pub t_end_s: f64,
    /// Compressed column data.
    pub data: Vec<u8>,
}

/// A stored block could not be decoded (corrupt or from an incompatible version).
#[derive(Debug, thiserror::Error)]
#[error("track block {index} is corrupt: {reason}")]
pub struct BlockError {
    pub index: i64,
    pub reason: String,
}

fn f64_columns(s: &TrackSample) -> [f64; F64_COLUMNS] {
    [
        s.time_s,
        s.normal_force_n,
        s.slip_velocity_m_s[0],
        s.slip_velocity_m_s[1],
        s.slip_velocity_m_s[2],
        s.slip_speed_m_s,
        s.penetration_m,
        s.penetration_rate_m_s,
        s.area_m2,
        s.pressure_pa,
        s.point_in_a_m[0],
        s.point_in_a_m[1],
        s.point_in_a_m[2],
        s.point_in_b_m[0],
        s.point_in_b_m[1],
        s.point_in_b_m[2],
    ]
}

/// Cut `samples` into blocks of at most `block_samples` and encode each.
pub fn encode_blocks(samples: &[TrackSample], block_samples: usize) -> Vec<TrackBlock> {
    samples
        .chunks(block_samples.max(1))
        .enumerate()
        .map(|(index, chunk)| encode_block(index as i64, chunk))
        .collect()
}

fn encode_block(index: i64, chunk: &[TrackSample]) -> TrackBlock {
    let n = chunk.len();
    let mut raw = Vec::with_capacity(n * BYTES_PER_SAMPLE);
    let rows: Vec<[f64; F64_COLUMNS]> = chunk.iter().map(f64_columns).collect();
    for column in 0..F64_COLUMNS {
        for row in &rows {
            raw.extend_from_slice(&row[column].to_le_bytes());
        }
    }
    for s in chunk {
        raw.extend_from_slice(&s.contact.to_le_bytes());
    }
    for s in chunk {
        raw.extend_from_slice(&s.track.to_le_bytes());
    }
    let mut encoder = ZlibEncoder::new(Vec::new(), Compression::fast());
    // Writing into a Vec cannot fail.
    let data: Vec<u8> = encoder
        .write_all(&raw)
        .and_then(|_| encoder.finish())
        .unwrap_or_default();
    TrackBlock {
        index,
        samples: n as i64,
        t_start_s: chunk.first().map_or(0.0, |s| s.time_s),
        t_end_s: chunk.last().map_or(0.0, |s| s.time_s),
        data,
    }
}

/// Decode one block back into samples.
pub fn decode_block(block: &TrackBlock) -> Result<Vec<TrackSample>, BlockError> {
    let fail = |reason: String| BlockError {
        index: block.index,
        reason,
    };
    let n = usize::try_from(block.samples).map_err(|_| fail("negative sample count".into()))?;
    let mut raw = Vec::with_capacity(n * BYTES_PER_SAMPLE);
    ZlibDecoder::new(block.data.as_slice())
        .read_to_end(&mut raw)
        .map_err(|e| fail(e.to_string()))?;
    if raw.len() != n * BYTES_PER_SAMPLE {
        return Err(fail(format!(
            "{} bytes for {n} samples, expected {}",
            raw.len(),
            n * BYTES_PER_SAMPLE
        )));
    }
    let f = |column: usize, row: usize| {
        let at = (column * n + row) * 8;
        let mut bytes = [0u8; 8];
        bytes.copy_from_slice(&raw[at..at + 8]);
        f64::from_le_bytes(bytes)
    };
    let u = |column: usize, row: usize| {
        let at = F64_COLUMNS * n * 8 + (column * n + row) * 4;
        let mut bytes = [0u8; 4];
        bytes.copy_from_slice(&raw[at..at + 4]);
        u32::from_le_bytes(bytes)
    };
    Ok((0..n)
        .map(|r| TrackSample {
            time_s: f(0, r),
            contact: u(0, r),
            track: u(1, r),
            normal_force_n: f(1, r),
            slip_velocity_m_s: [f(2, r), f(3, r), f(4, r)],
            slip_speed_m_s: f(5, r),
            penetration_m: f(6, r),
            penetration_rate_m_s: f(7, r),
            area_m2: f(8, r),
            pressure_pa: f(9, r),
            point_in_a_m: [f(10, r), f(11, r), f(12, r)],
            point_in_b_m: [f(13, r), f(14, r), f(15, r)],
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::physics::track::example_sample as sample;

    #[test]
    fn blocks_round_trip_bit_exact() {
        let samples: Vec<TrackSample> = (0..10_001).map(sample).collect();
        let blocks = encode_blocks(&samples, 4096);
        assert_eq!(blocks.len(), 3);
        assert_eq!(blocks.iter().map(|b| b.samples).sum::<i64>(), 10_001);
        let decoded: Vec<TrackSample> = blocks
            .iter()
            .flat_map(|b| decode_block(b).unwrap())
            .collect();
        assert_eq!(decoded, samples);
        // Columnar + deflate must beat the raw 136 bytes/sample on smooth data.
        let stored: usize = blocks.iter().map(|b| b.data.len()).sum();
        assert!(
            stored < samples.len() * BYTES_PER_SAMPLE / 2,
            "stored {stored}"
        );
    }

    #[test]
    fn corrupt_block_is_an_error_not_a_panic() {
        let mut block = encode_blocks(&[sample(1), sample(2)], 10).remove(0);
        block.samples = 3;
        assert!(decode_block(&block).is_err());
        block.data = vec![1, 2, 3];
        assert!(decode_block(&block).is_err());
    }
}
