//! The hostile probes of an open network, repeated on every CI run against an in-process service
//! with short limits: slow clients (partial heads, bodies shorter than their Content-Length,
//! floods of idle connections) are cut off within the configured timeouts and the caps answer
//! 429/503 problem+json; an Idempotency-Key is the caller's own; and the nonsense an earlier
//! hostile pass found accepted is refused naming the field.

use crate::helpers::{Api, TestApp};
use crate::support::{ADMIN, ENGINEER, PLANNER};
use serde_json::json;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

const HEAD_TIMEOUT_S: f64 = 1.0;
const BODY_TIMEOUT_S: f64 = 1.0;
const PER_PEER: usize = 40;

async fn hostile_app() -> TestApp {
    TestApp::spawn_with(crate::helpers::Runner::Counting, false, |c| {
        c.header_read_timeout_s = HEAD_TIMEOUT_S;
        c.body_read_timeout_s = BODY_TIMEOUT_S;
        c.max_connections = 4 * PER_PEER;
        c.max_connections_per_peer = PER_PEER;
    })
    .await
}

fn addr(api: &Api) -> String {
    api.base.trim_start_matches("http://").to_string()
}

/// Everything the server sends on `stream` until it closes (or `limit` passes: then panics).
fn read_until_closed(stream: &mut TcpStream, limit: Duration) -> Vec<u8> {
    stream.set_read_timeout(Some(limit)).expect("read timeout");
    let mut out = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        match stream.read(&mut buf) {
            Ok(0) => return out,
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => return out,
            Err(e) => panic!("the server kept the connection open past {limit:?}: {e}"),
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn partial_heads_are_closed_within_the_timeout_and_the_per_peer_cap_answers_429() {
    let app = hostile_app().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let addr = addr(&api);
        let started = Instant::now();
        // Three times the per-address cap of half-sent heads from one address.
        let mut streams: Vec<TcpStream> = (0..3 * PER_PEER)
            .map(|_| {
                let mut s = TcpStream::connect(&addr).expect("connect");
                let _ = s.write_all(b"GET /v1/jobs HTTP/1.1\r\nHost: x\r\nX-Slow: ");
                s
            })
            .collect();
        let (mut refused, mut closed) = (0, 0);
        for s in &mut streams {
            let answer = read_until_closed(s, Duration::from_secs_f64(HEAD_TIMEOUT_S + 5.0));
            let text = String::from_utf8_lossy(&answer);
            if text.starts_with("HTTP/1.1 429") {
                assert!(text.contains("application/problem+json"), "{text}");
                assert!(text.contains("max_connections_per_peer"), "{text}");
                refused += 1;
            } else {
                closed += 1;
            }
        }
        let elapsed = started.elapsed().as_secs_f64();
        assert_eq!(closed, PER_PEER, "the cap's worth were held, then closed");
        assert_eq!(refused, 2 * PER_PEER, "the rest were refused at once");
        assert!(
            elapsed < HEAD_TIMEOUT_S + 5.0,
            "every partial head was closed by the header timeout ({elapsed:.1} s)"
        );
        // The places came back: a whole request is served.
        let r = api.get("/v1/jobs", Some(ENGINEER));
        assert_eq!(r.status, 200, "{}", r.body);
    })
    .await
    .expect("probe thread");
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_body_shorter_than_its_content_length_is_answered_408() {
    let app = hostile_app().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        let addr = addr(&api);
        let mut s = TcpStream::connect(&addr).expect("connect");
        let head = format!(
            "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer {ENGINEER}\r\n\
             Content-Type: application/json\r\nContent-Length: 100\r\n\r\n{{\"kind\":"
        );
        s.write_all(head.as_bytes()).expect("write");
        let started = Instant::now();
        let answer = read_until_closed(&mut s, Duration::from_secs_f64(BODY_TIMEOUT_S + 5.0));
        let text = String::from_utf8_lossy(&answer);
        assert!(text.starts_with("HTTP/1.1 408"), "{text}");
        assert!(text.contains("application/problem+json"), "{text}");
        assert!(text.contains("body_read_timeout_s"), "{text}");
        assert!(started.elapsed().as_secs_f64() < BODY_TIMEOUT_S + 5.0);
        // Nothing was stored.
        let r = api.get("/v1/jobs", Some(ENGINEER));
        assert_eq!(r.json()["items"].as_array().map_or(0, Vec::len), 0);
    })
    .await
    .expect("probe thread");
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_idempotency_key_is_the_callers_own() {
    let app = hostile_app().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // A second engineer's token.
        let r = api.post(
            "/v1/tokens",
            Some(ADMIN),
            &json!({"name": "eng-2", "role": "engineer"}).to_string(),
        );
        assert_eq!(r.status, 201, "{}", r.body);
        let second = r.json()["token"].as_str().expect("token").to_string();
        let body = json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": 1}})
            .to_string();
        let key = [("Idempotency-Key", "case-c-run-1")];
        let first = api.request("POST", "/v1/jobs", Some(ENGINEER), &key, Some(&body));
        assert_eq!(first.status, 201, "{}", first.body);
        // The same key and body from another token: a job of its own, not the first one's.
        let other = api.request("POST", "/v1/jobs", Some(&second), &key, Some(&body));
        assert_eq!(other.status, 201, "{}", other.body);
        assert_ne!(first.json()["id"], other.json()["id"]);
        assert_eq!(other.json()["submitted_by"], "eng-2");
        // Another body under that key from the other token: its own conflict, naming its job.
        let changed = json!({"kind": "simulate", "params": {"config": "rattle-box-c", "seed": 2}})
            .to_string();
        let p = api
            .request("POST", "/v1/jobs", Some(&second), &key, Some(&changed))
            .problem(422);
        let other_id = other.json()["id"].as_str().expect("id").to_string();
        assert!(
            p["detail"].as_str().is_some_and(|d| d.contains(&other_id)),
            "{p}"
        );
        // Each token's retry replays its own job.
        let again = api.request("POST", "/v1/jobs", Some(ENGINEER), &key, Some(&body));
        assert_eq!(again.status, 200);
        assert_eq!(again.json()["id"], first.json()["id"]);
        // Two Idempotency-Key headers are refused.
        let two = [("Idempotency-Key", "a"), ("Idempotency-Key", "b")];
        let p = api
            .request("POST", "/v1/jobs", Some(ENGINEER), &two, Some(&body))
            .problem(400);
        assert_eq!(p["field"], "Idempotency-Key");
    })
    .await
    .expect("probe thread");
    app.stop().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn nonsense_is_refused_naming_the_field() {
    let app = hostile_app().await;
    let api = app.api.clone();
    tokio::task::spawn_blocking(move || {
        // A control character in a measurement's free text.
        let m = json!({
            "dimensions_mm": railwear::analysis::rattle_space::LauncherDimensions::design(),
            "measured_by": "tech\u{1b}[31m",
            "measured_at": "2024-05-01T08:30:00Z",
            "location": "Depot 7",
        });
        let p = api
            .post("/v1/rails/R-1/measurements", Some(PLANNER), &m.to_string())
            .problem(422);
        assert_eq!(p["field"], "measured_by");
        // A design life past any service: a unit mistake.
        let p = api
            .get("/v1/rails/R-1/report?design_life_h=1e308", Some(PLANNER))
            .problem(400);
        assert_eq!(p["field"], "design_life_h");
        // A repeated query key is named as such.
        let id = uuid::Uuid::new_v4();
        let p = api
            .get(
                &format!("/v1/jobs/{id}/tracks?format=csv&format=json"),
                Some(ENGINEER),
            )
            .problem(400);
        assert_eq!(p["field"], "format");
        // A token name with a control character.
        let p = api
            .post(
                "/v1/tokens",
                Some(ADMIN),
                &json!({"name": "a\nb", "role": "engineer"}).to_string(),
            )
            .problem(422);
        assert_eq!(p["field"], "name");
    })
    .await
    .expect("probe thread");
    app.stop().await;
}
