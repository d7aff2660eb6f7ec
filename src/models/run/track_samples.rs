//! The track samples a run records for export: each active track at an accepted step, its
//! contact point in both bodies' frames.

use crate::physics::contact::TrackState;
use crate::physics::simulate::StepView;
use crate::physics::system::MultibodySystem;
use crate::physics::track::TrackSample;

/// Appends a sample of every active track of step `v` to `out`.
pub(super) fn record_tracks(v: &StepView, out: &mut Vec<TrackSample>) {
    let sys = v.system;
    let mut ws = sys.workspace();
    sys.frames(v.t, v.state, &mut ws);
    for tr in v.tracks {
        out.push(track_sample(v.t, tr, sys, &ws.frames));
    }
}

fn track_sample(
    t: f64,
    tr: &TrackState,
    sys: &MultibodySystem,
    frames: &[crate::physics::body::BodyFrame],
) -> TrackSample {
    let c = &sys.contacts[tr.contact as usize];
    let pa = frames[c.body_a].to_local(&tr.point);
    let pb = frames[c.body_b].to_local(&tr.point);
    TrackSample {
        time_s: t,
        contact: tr.contact,
        track: tr.track,
        normal_force_n: tr.normal_force,
        slip_velocity_m_s: [tr.slip_velocity.x, tr.slip_velocity.y, tr.slip_velocity.z],
        slip_speed_m_s: tr.slip_speed,
        penetration_m: tr.penetration,
        penetration_rate_m_s: tr.penetration_rate,
        area_m2: tr.area,
        pressure_pa: tr.pressure(),
        point_in_a_m: [pa.x, pa.y, pa.z],
        point_in_b_m: [pb.x, pb.y, pb.z],
    }
}
