//! Refusals made below axum answer problem+json too (issue 29: a control character in
//! `Idempotency-Key` got a bare 400 with no body).
//!
//! hyper refuses a request whose head it cannot parse (a header value with a control
//! character, a malformed method, target or version; headers or a target too long) before
//! any router sees it, with a bodiless `400`, `431` or `414`, and closes the connection.
//! hyper offers no hook for that answer, so the accept loop ([`super::server`]) wraps each
//! connection and rewrites it on its way out: a `4xx` head with `content-length: 0` and no
//! content type is one of these (every answer of the service itself carries a problem body,
//! [`super::problem`]).
//! Everything else passes through untouched.

use super::problem::Problem;
use axum::http::StatusCode;
use std::io;
use std::pin::Pin;
use std::task::{Context, Poll};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};

/// A connection whose bare `4xx` answers (hyper's own) go out as problem+json.
pub struct ProblemIo<T> {
    inner: T,
    rewrite: Option<Rewrite>,
}

/// A replacement being written in place of `original_len` bytes hyper handed over.
struct Rewrite {
    bytes: Vec<u8>,
    written: usize,
    original_len: usize,
}

impl<T> ProblemIo<T> {
    pub fn new(inner: T) -> Self {
        Self {
            inner,
            rewrite: None,
        }
    }
}

/// The problem+json answer for `head`, if it is hyper's bodiless refusal of a request head.
pub fn replacement_for(head: &[u8]) -> Option<Vec<u8>> {
    let text = std::str::from_utf8(head).ok()?;
    let status_line = text.split("\r\n").next()?;
    let mut parts = status_line.splitn(3, ' ');
    let version = parts.next()?;
    let code: u16 = parts.next()?.parse().ok()?;
    if !(version == "HTTP/1.1" || version == "HTTP/1.0") || !(400..500).contains(&code) {
        return None;
    }
    let lower = text.to_ascii_lowercase();
    if !text.ends_with("\r\n\r\n")
        || !lower.contains("\r\ncontent-length: 0\r\n")
        || lower.contains("\r\ncontent-type:")
    {
        return None;
    }
    let status = StatusCode::from_u16(code).ok()?;
    let detail = match status {
        StatusCode::BAD_REQUEST => {
            "the request head is malformed: a header value holds a character HTTP does not \
             allow (a control character), or the method, target or version is invalid"
        }
        StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE => "the request's headers are too large",
        StatusCode::URI_TOO_LONG => "the request target is too long",
        _ => "the request was refused before it reached the service",
    };
    let problem = Problem::new(status, "bad-request-head", "Malformed request head", detail);
    closing_answer(status_line, &problem, "")
}

/// A whole HTTP/1.1 answer carrying `problem` as problem+json under `status_line`, with the
/// header lines `extra` (each ending in CRLF), that closes the connection: for answers written
/// below axum (hyper's refusals here, the connection caps in [`super::server`]).
pub(super) fn closing_answer(status_line: &str, problem: &Problem, extra: &str) -> Option<Vec<u8>> {
    let body = serde_json::to_vec(problem).ok()?;
    let mut out = format!(
        "{status_line}\r\ncontent-type: application/problem+json\r\ncontent-length: {}\r\n\
         {extra}connection: close\r\n\r\n",
        body.len()
    )
    .into_bytes();
    out.extend_from_slice(&body);
    Some(out)
}

impl<T: AsyncRead + Unpin> AsyncRead for ProblemIo<T> {
    fn poll_read(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().inner).poll_read(cx, buf)
    }
}

impl<T: AsyncWrite + Unpin> AsyncWrite for ProblemIo<T> {
    fn poll_write(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        let this = self.get_mut();
        if this.rewrite.is_none() {
            match replacement_for(buf) {
                Some(bytes) => {
                    tracing::debug!("a request head hyper refused is answered as problem+json");
                    this.rewrite = Some(Rewrite {
                        bytes,
                        written: 0,
                        original_len: buf.len(),
                    });
                }
                None => return Pin::new(&mut this.inner).poll_write(cx, buf),
            }
        }
        let Some(rewrite) = this.rewrite.as_mut() else {
            return Pin::new(&mut this.inner).poll_write(cx, buf);
        };
        while rewrite.written < rewrite.bytes.len() {
            match Pin::new(&mut this.inner).poll_write(cx, &rewrite.bytes[rewrite.written..]) {
                Poll::Ready(Ok(0)) => return Poll::Ready(Err(io::ErrorKind::WriteZero.into())),
                Poll::Ready(Ok(n)) => rewrite.written += n,
                Poll::Ready(Err(e)) => return Poll::Ready(Err(e)),
                Poll::Pending => return Poll::Pending,
            }
        }
        // The whole of hyper's head is accounted for by the replacement.
        let consumed = rewrite.original_len;
        this.rewrite = None;
        Poll::Ready(Ok(consumed))
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().inner).poll_flush(cx)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_bodiless_4xx_head_is_rewritten() {
        let bare = b"HTTP/1.1 400 Bad Request\r\ncontent-length: 0\r\ndate: Thu, 26 Nov 2026 10:00:00 GMT\r\n\r\n";
        let out = String::from_utf8(replacement_for(bare).unwrap()).unwrap();
        assert!(out.starts_with("HTTP/1.1 400 Bad Request\r\n"), "{out}");
        assert!(
            out.contains("content-type: application/problem+json"),
            "{out}"
        );
        let (head, body) = out.split_once("\r\n\r\n").unwrap();
        assert!(
            head.contains(&format!("content-length: {}", body.len())),
            "{out}"
        );
        let p: serde_json::Value = serde_json::from_str(body).unwrap();
        assert_eq!(p["status"], 400);
        // The service's own answers pass through: a problem with its body, a success.
        let problem = b"HTTP/1.1 400 Bad Request\r\ncontent-type: application/problem+json\r\ncontent-length: 90\r\n\r\n";
        assert!(replacement_for(problem).is_none());
        assert!(replacement_for(b"HTTP/1.1 200 OK\r\ncontent-length: 0\r\n\r\n").is_none());
        assert!(replacement_for(b"{\"a\": 1}").is_none());
    }
}
