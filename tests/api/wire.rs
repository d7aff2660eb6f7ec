//! Requests a conforming HTTP client will not send as written, for the tests that probe the
//! server's answer to them: a path with percent-encoded dot segments (`/v1/rails/%2E/...`,
//! which a client following the URL standard, reqwest included, resolves away before sending)
//! and an oversized body the server answers before reading it (hyper's client reports the
//! server closing mid-body as a send error, not as the early answer). Everything else goes
//! through the testkit's reqwest client ([`crate::helpers::Api::request`]).
//!
//! One request per connection (`Connection: close`), read to the end; a failed write still
//! reads the answer the server sent before it closed.

use crate::helpers::Reply;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

/// `method path` with an optional bearer token and JSON body, sent as is to `base`
/// (`http://host:port`).
pub fn send(base: &str, method: &str, path: &str, token: Option<&str>, body: &str) -> Reply {
    let addr = base.trim_start_matches("http://");
    let mut stream = TcpStream::connect(addr).unwrap_or_else(|e| panic!("connect {addr}: {e}"));
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .expect("read timeout");
    let mut head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n",
        body.len()
    );
    if let Some(token) = token {
        head.push_str(&format!("Authorization: Bearer {token}\r\n"));
    }
    head.push_str("\r\n");
    // The server may answer and close before the body is through: the write then fails, and
    // the answer is still there to read.
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body.as_bytes()));
    let mut raw = Vec::new();
    let read = stream.read_to_end(&mut raw);
    assert!(!raw.is_empty(), "{method} {path}: no answer ({read:?})");
    let text = String::from_utf8_lossy(&raw);
    let (head, rest) = text
        .split_once("\r\n\r\n")
        .expect("a complete response head");
    let mut lines = head.lines();
    let status = lines
        .next()
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|s| s.parse().ok())
        .expect("status line");
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    let length = headers
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("content-length"))
        .and_then(|(_, v)| v.parse::<usize>().ok())
        .unwrap_or(rest.len());
    Reply {
        status,
        body: rest.chars().take(length).collect(),
        headers,
    }
}
