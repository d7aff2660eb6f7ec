//! The accept loop: each connection served by hyper's HTTP/1 (or HTTP/2) with a timeout on
//! reading a request's head, a deadline on reading its body, and caps on the connections held
//! at once, in all and per peer address. axum's own `serve` sets none of these (it gives hyper
//! no timer, so hyper's header timeout never fires), and a client that opens connections and
//! sends half a head, or a body shorter than its `Content-Length`, held the server's memory and
//! descriptors for as long as it liked.
//!
//! - Head: hyper's `header_read_timeout` (it closes the connection; no answer can be framed for a
//!   request whose head never arrived).
//! - Body: [`BodyDeadline`] from the head's arrival to the body's end; the JSON readers answer
//!   408 problem+json when it passes ([`super::problem`]).
//! - Caps: one connection over [`Limits::max_connections`] is answered 503, one over
//!   [`Limits::max_connections_per_peer`] from the same address 429, as problem+json with
//!   `Retry-After` and `Connection: close`, written before anything is read (a server may answer
//!   early), within a short write deadline so a client that does not read cannot hold the task.

use super::connection::{closing_answer, ProblemIo};
use super::problem::{BodyDeadlinePassed, Problem};
use axum::extract::Request;
use axum::http::StatusCode;
use axum::middleware::Next;
use axum::response::Response;
use axum::Router;
use hyper_util::rt::{TokioExecutor, TokioIo, TokioTimer};
use hyper_util::server::conn::auto::Builder;
use hyper_util::service::TowerToHyperService;
use std::collections::HashMap;
use std::future::Future;
use std::net::{IpAddr, SocketAddr};
use std::pin::Pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::AsyncWriteExt;
use tokio::net::{TcpListener, TcpStream};
use tower::ServiceExt;

/// How long a refusal (429/503) may take to write before the connection is dropped unanswered.
const REFUSAL_WRITE_TIMEOUT: Duration = Duration::from_secs(2);

/// The connection settings of the service (configs/service.toml).
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Time to send a request's head; also the idle time of a keep-alive connection.
    pub header_read_timeout: Duration,
    /// Time from a request's head to the end of its body.
    pub body_read_timeout: Duration,
    /// Connections held at once.
    pub max_connections: usize,
    /// Connections held at once from one peer address.
    pub max_connections_per_peer: usize,
}

/// Open connections, in all and per peer address.
#[derive(Debug, Default)]
struct Census {
    total: usize,
    per_peer: HashMap<IpAddr, usize>,
}

/// A held connection's place in the [`Census`]; given back when dropped.
struct Admitted {
    census: Arc<Mutex<Census>>,
    peer: IpAddr,
}

impl Drop for Admitted {
    fn drop(&mut self) {
        let mut census = lock(&self.census);
        census.total = census.total.saturating_sub(1);
        if let Some(n) = census.per_peer.get_mut(&self.peer) {
            *n -= 1;
            if *n == 0 {
                census.per_peer.remove(&self.peer);
            }
        }
    }
}

fn lock(census: &Mutex<Census>) -> std::sync::MutexGuard<'_, Census> {
    match census.lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    }
}

/// A place for a connection from `peer`, or the refusal to send it.
fn admit(census: &Arc<Mutex<Census>>, peer: IpAddr, limits: &Limits) -> Result<Admitted, Problem> {
    let mut c = lock(census);
    if c.total >= limits.max_connections {
        return Err(Problem::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "too-many-connections",
            "Too many connections",
            format!(
                "the server holds its limit of {} connections (max_connections); retry shortly",
                limits.max_connections
            ),
        ));
    }
    let from_peer = c.per_peer.get(&peer).copied().unwrap_or(0);
    if from_peer >= limits.max_connections_per_peer {
        return Err(Problem::new(
            StatusCode::TOO_MANY_REQUESTS,
            "too-many-connections-from-peer",
            "Too many connections from one address",
            format!(
                "this address holds {} open connections, the limit per address \
                 (max_connections_per_peer); reuse a connection or close one",
                limits.max_connections_per_peer
            ),
        ));
    }
    c.total += 1;
    *c.per_peer.entry(peer).or_insert(0) += 1;
    Ok(Admitted {
        census: Arc::clone(census),
        peer,
    })
}

/// The whole HTTP/1.1 answer for a refused connection.
fn refusal_bytes(problem: &Problem) -> Vec<u8> {
    let status = StatusCode::from_u16(problem.status).unwrap_or(StatusCode::SERVICE_UNAVAILABLE);
    let status_line = format!(
        "HTTP/1.1 {} {}",
        status.as_u16(),
        status.canonical_reason().unwrap_or("")
    );
    closing_answer(&status_line, problem, "retry-after: 1\r\n").unwrap_or_default()
}

async fn refuse(mut stream: TcpStream, problem: Problem) {
    let bytes = refusal_bytes(&problem);
    let _ = tokio::time::timeout(REFUSAL_WRITE_TIMEOUT, async {
        stream.write_all(&bytes).await?;
        stream.shutdown().await
    })
    .await;
}

/// Serve `router` on `listener` until `shutdown` resolves, then stop accepting, let each open
/// connection finish its request in flight, and return when all are closed.
pub async fn serve(
    listener: TcpListener,
    router: Router,
    limits: Limits,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let census = Arc::new(Mutex::new(Census::default()));
    let graceful = hyper_util::server::graceful::GracefulShutdown::new();
    let mut builder = Builder::new(TokioExecutor::new());
    builder
        .http1()
        .timer(TokioTimer::new())
        .header_read_timeout(limits.header_read_timeout);
    let router = router.layer(axum::middleware::from_fn_with_state(
        limits.body_read_timeout,
        body_deadline,
    ));
    tokio::pin!(shutdown);
    loop {
        let (stream, peer): (TcpStream, SocketAddr) = tokio::select! {
            accepted = listener.accept() => match accepted {
                Ok(pair) => pair,
                Err(e) => {
                    // Out of descriptors or a connection reset before it was taken: wait a
                    // little rather than spin, as axum's loop does.
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
            () = &mut shutdown => break,
        };
        let admitted = match admit(&census, peer.ip(), &limits) {
            Ok(admitted) => admitted,
            Err(problem) => {
                tracing::debug!(%peer, status = problem.status, "connection refused at the cap");
                tokio::spawn(refuse(stream, problem));
                continue;
            }
        };
        let _ = stream.set_nodelay(true);
        let service = router
            .clone()
            .map_request(|request: Request<hyper::body::Incoming>| {
                request.map(axum::body::Body::new)
            });
        let connection = builder
            .serve_connection_with_upgrades(
                TokioIo::new(ProblemIo::new(stream)),
                TowerToHyperService::new(service),
            )
            .into_owned();
        let connection = graceful.watch(connection);
        tokio::spawn(async move {
            let _place = admitted;
            if let Err(e) = connection.await {
                tracing::debug!(%peer, error = %e, "connection ended with an error");
            }
        });
    }
    drop(listener);
    graceful.shutdown().await;
    Ok(())
}

/// Puts each request's body under a deadline of `timeout` from now (the head has arrived).
async fn body_deadline(
    axum::extract::State(timeout): axum::extract::State<Duration>,
    request: Request,
    next: Next,
) -> Response {
    let request = request.map(|body| axum::body::Body::new(BodyDeadline::new(body, timeout)));
    next.run(request).await
}

/// A request body that fails with [`BodyDeadlinePassed`] when it has not ended by its deadline.
pub struct BodyDeadline {
    inner: axum::body::Body,
    timeout: Duration,
    sleep: Pin<Box<tokio::time::Sleep>>,
}

impl BodyDeadline {
    fn new(inner: axum::body::Body, timeout: Duration) -> Self {
        Self {
            inner,
            timeout,
            sleep: Box::pin(tokio::time::sleep(timeout)),
        }
    }
}

impl http_body::Body for BodyDeadline {
    type Data = axum::body::Bytes;
    type Error = axum::BoxError;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<http_body::Frame<Self::Data>, Self::Error>>> {
        let this = &mut *self;
        match Pin::new(&mut this.inner).poll_frame(cx) {
            Poll::Ready(frame) => Poll::Ready(frame.map(|f| f.map_err(Into::into))),
            Poll::Pending => match this.sleep.as_mut().poll(cx) {
                Poll::Ready(()) => {
                    Poll::Ready(Some(Err(Box::new(BodyDeadlinePassed(this.timeout)))))
                }
                Poll::Pending => Poll::Pending,
            },
        }
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> http_body::SizeHint {
        self.inner.size_hint()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(total: usize, per_peer: usize) -> Limits {
        Limits {
            header_read_timeout: Duration::from_secs(1),
            body_read_timeout: Duration::from_secs(1),
            max_connections: total,
            max_connections_per_peer: per_peer,
        }
    }

    #[test]
    fn the_census_refuses_past_each_cap_and_frees_places_on_drop() {
        let census = Arc::new(Mutex::new(Census::default()));
        let a: IpAddr = "10.0.0.1".parse().expect("address");
        let b: IpAddr = "10.0.0.2".parse().expect("address");
        let l = limits(3, 2);
        let first = admit(&census, a, &l).expect("1st from a");
        let _second = admit(&census, a, &l).expect("2nd from a");
        assert_eq!(admit(&census, a, &l).err().map(|p| p.status), Some(429));
        let _third = admit(&census, b, &l).expect("1st from b");
        assert_eq!(admit(&census, b, &l).err().map(|p| p.status), Some(503));
        drop(first);
        let _again = admit(&census, a, &l).expect("a place came back");
        assert_eq!(lock(&census).total, 3);
    }

    #[test]
    fn a_refusal_is_a_whole_problem_json_answer_that_closes() {
        let p = Problem::new(StatusCode::TOO_MANY_REQUESTS, "x", "X", "detail");
        let text = String::from_utf8(refusal_bytes(&p)).expect("ascii");
        let (head, body) = text.split_once("\r\n\r\n").expect("head and body");
        assert!(head.starts_with("HTTP/1.1 429 Too Many Requests\r\n"));
        assert!(head.contains("content-type: application/problem+json"));
        assert!(head.contains("connection: close"));
        assert!(head.contains(&format!("content-length: {}", body.len())));
        let v: serde_json::Value = serde_json::from_str(body).expect("json body");
        assert_eq!(v["status"], 429);
    }
}
