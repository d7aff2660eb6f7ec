//! One small HTTP/1.1 client on tokio, enough for the service's own API: requests with headers
//! and a body, responses with `Content-Length`, chunked or read-to-close bodies. No TLS, no
//! redirects, no compression (the service sends none).
//!
//! [`Conn`] keeps one keep-alive connection (the load benchmark: one per task); [`Client`]
//! opens a connection per request (`Connection: close`), so it is `&self`, cheap to clone and
//! never holds an idle connection that a graceful shutdown would wait for (the tests).

use std::time::Duration;
use tokio::io::{AsyncBufRead, AsyncBufReadExt, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpStream;

/// How long one request may take, connect to last body byte, unless set otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(60);

#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    #[error("HTTP I/O: {0}")]
    Io(#[from] std::io::Error),
    #[error("no complete response within {0:?}")]
    Timeout(Duration),
    #[error("malformed response: {0}")]
    Malformed(String),
}

/// One request: method, path (with query), headers and an optional body.
#[derive(Debug, Clone)]
pub struct Request {
    pub method: String,
    pub path: String,
    pub headers: Vec<(String, String)>,
    pub body: Option<Vec<u8>>,
}

impl Request {
    pub fn new(method: &str, path: &str) -> Self {
        Request {
            method: method.to_string(),
            path: path.to_string(),
            headers: Vec::new(),
            body: None,
        }
    }

    pub fn get(path: &str) -> Self {
        Self::new("GET", path)
    }

    pub fn post(path: &str) -> Self {
        Self::new("POST", path)
    }

    pub fn header(mut self, name: &str, value: &str) -> Self {
        self.headers.push((name.to_string(), value.to_string()));
        self
    }

    /// `Authorization: Bearer <token>`.
    pub fn bearer(self, token: &str) -> Self {
        self.header("Authorization", &format!("Bearer {token}"))
    }

    /// A body sent as is (give its `Content-Type` with [`Request::header`]).
    pub fn body(mut self, body: impl Into<Vec<u8>>) -> Self {
        self.body = Some(body.into());
        self
    }

    /// A JSON body: `Content-Type: application/json` unless a content type was given already.
    pub fn json(self, body: impl Into<Vec<u8>>) -> Self {
        let typed = self.has_header("content-type");
        let r = self.body(body);
        if typed {
            r
        } else {
            r.header("Content-Type", "application/json")
        }
    }

    fn has_header(&self, name: &str) -> bool {
        self.headers
            .iter()
            .any(|(k, _)| k.eq_ignore_ascii_case(name))
    }

    /// The request's bytes on the wire.
    fn encode(&self, host: &str, close: bool) -> Vec<u8> {
        let mut head = format!("{} {} HTTP/1.1\r\nHost: {host}\r\n", self.method, self.path);
        for (k, v) in &self.headers {
            head.push_str(&format!("{k}: {v}\r\n"));
        }
        if let Some(body) = &self.body {
            head.push_str(&format!("Content-Length: {}\r\n", body.len()));
        }
        if close {
            head.push_str("Connection: close\r\n");
        }
        head.push_str("\r\n");
        let mut out = head.into_bytes();
        if let Some(body) = &self.body {
            out.extend_from_slice(body);
        }
        out
    }
}

/// One response: status, headers in order, body bytes.
#[derive(Debug, Clone)]
pub struct Response {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Response {
    /// The first header of this name (case-insensitive).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// The body as text (invalid UTF-8 replaced).
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }

    pub fn json(&self) -> Result<serde_json::Value, serde_json::Error> {
        serde_json::from_slice(&self.body)
    }
}

/// `host:port` of an address given as `http://host:port[/...]` or `host:port`.
fn host_port(addr: &str) -> String {
    let rest = addr.strip_prefix("http://").unwrap_or(addr);
    rest.split('/').next().unwrap_or(rest).to_string()
}

/// A client that opens one connection per request; clone it freely.
#[derive(Debug, Clone)]
pub struct Client {
    addr: String,
    timeout: Duration,
}

impl Client {
    /// A client of the server at `addr` (`127.0.0.1:8080` or `http://127.0.0.1:8080`).
    pub fn new(addr: &str) -> Self {
        Client {
            addr: host_port(addr),
            timeout: DEFAULT_TIMEOUT,
        }
    }

    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// `host:port` of the server.
    pub fn addr(&self) -> &str {
        &self.addr
    }

    pub async fn send(&self, request: &Request) -> Result<Response, ClientError> {
        let exchange = async {
            let stream = TcpStream::connect(&self.addr).await?;
            stream.set_nodelay(true)?;
            let mut stream = BufReader::new(stream);
            exchange(
                &mut stream,
                &request.encode(&self.addr, true),
                &request.method,
            )
            .await
        };
        match tokio::time::timeout(self.timeout, exchange).await {
            Ok(Ok((response, _))) => Ok(response),
            Ok(Err(Exchange { error, .. })) => Err(error),
            Err(_) => Err(ClientError::Timeout(self.timeout)),
        }
    }
}

/// One keep-alive connection, reopened when the server closed it.
#[derive(Debug)]
pub struct Conn {
    addr: String,
    timeout: Duration,
    stream: Option<BufReader<TcpStream>>,
}

impl Conn {
    pub fn new(addr: &str) -> Self {
        Conn {
            addr: host_port(addr),
            timeout: DEFAULT_TIMEOUT,
            stream: None,
        }
    }

    /// One request. A kept connection that fails before the first response byte (the server
    /// closed it while idle) is replaced by a new one and the request sent once more.
    pub async fn send(&mut self, request: &Request) -> Result<Response, ClientError> {
        let timeout = self.timeout;
        match tokio::time::timeout(timeout, self.send_inner(request)).await {
            Ok(r) => r,
            Err(_) => {
                self.stream = None;
                Err(ClientError::Timeout(timeout))
            }
        }
    }

    async fn send_inner(&mut self, request: &Request) -> Result<Response, ClientError> {
        let bytes = request.encode(&self.addr, false);
        let reused = self.stream.is_some();
        let first = self.exchange_once(&bytes, &request.method).await;
        match first {
            Err(Exchange {
                answered: false, ..
            }) if reused => {
                self.stream = None;
                self.exchange_once(&bytes, &request.method)
                    .await
                    .map_err(|e| e.error)
            }
            other => other.map_err(|e| e.error),
        }
    }

    async fn exchange_once(&mut self, bytes: &[u8], method: &str) -> Result<Response, Exchange> {
        let stream = match self.stream.take() {
            Some(s) => s,
            None => {
                let s = TcpStream::connect(&self.addr)
                    .await
                    .map_err(Exchange::before)?;
                s.set_nodelay(true).map_err(Exchange::before)?;
                BufReader::new(s)
            }
        };
        let mut stream = stream;
        let (response, keep) = exchange(&mut stream, bytes, method).await?;
        if keep {
            self.stream = Some(stream);
        }
        Ok(response)
    }
}

/// A failed exchange, and whether any response byte had arrived.
struct Exchange {
    error: ClientError,
    answered: bool,
}

impl Exchange {
    fn before(e: impl Into<ClientError>) -> Self {
        Exchange {
            error: e.into(),
            answered: false,
        }
    }
    fn after(e: impl Into<ClientError>) -> Self {
        Exchange {
            error: e.into(),
            answered: true,
        }
    }
}

impl From<std::io::Error> for Exchange {
    fn from(e: std::io::Error) -> Self {
        Exchange::before(e)
    }
}

fn malformed(msg: impl Into<String>) -> ClientError {
    ClientError::Malformed(msg.into())
}

/// Write `bytes`, read one response. Returns it and whether the connection may be reused.
async fn exchange(
    stream: &mut BufReader<TcpStream>,
    bytes: &[u8],
    method: &str,
) -> Result<(Response, bool), Exchange> {
    // A server may answer before reading the whole body (413) and close: then the write fails
    // but the answer is still there to read.
    let written = stream.get_mut().write_all(bytes).await;
    let mut line = String::new();
    let n = match stream.read_line(&mut line).await {
        Ok(n) => n,
        Err(e) => return Err(Exchange::before(written.err().unwrap_or(e))),
    };
    if n == 0 {
        return Err(Exchange::before(match written {
            Err(e) => ClientError::Io(e),
            Ok(()) => malformed("connection closed before the status line"),
        }));
    }
    let status: u16 = line
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| Exchange::after(malformed(format!("status line {line:?}"))))?;
    let mut headers = Vec::new();
    loop {
        line.clear();
        if stream.read_line(&mut line).await.map_err(Exchange::after)? == 0 {
            return Err(Exchange::after(malformed(
                "connection closed in the headers",
            )));
        }
        let h = line.trim_end();
        if h.is_empty() {
            break;
        }
        if let Some((k, v)) = h.split_once(':') {
            headers.push((k.trim().to_string(), v.trim().to_string()));
        }
    }
    let mut response = Response {
        status,
        headers,
        body: Vec::new(),
    };
    let mut keep = written.is_ok()
        && !response
            .header("connection")
            .is_some_and(|v| v.eq_ignore_ascii_case("close"));
    let no_body = method.eq_ignore_ascii_case("HEAD")
        || status == 204
        || status == 304
        || (100..200).contains(&status);
    let chunked = response
        .header("transfer-encoding")
        .is_some_and(|v| v.eq_ignore_ascii_case("chunked"));
    let length = response.header("content-length").map(str::parse::<usize>);
    if no_body {
        // HEAD, 1xx, 204 and 304 have no body whatever the headers say.
    } else if chunked {
        response.body = read_chunked(stream).await.map_err(Exchange::after)?;
    } else if let Some(length) = length {
        let n = length.map_err(|_| Exchange::after(malformed("bad Content-Length")))?;
        response.body.resize(n, 0);
        stream
            .read_exact(&mut response.body)
            .await
            .map_err(Exchange::after)?;
    } else {
        stream
            .read_to_end(&mut response.body)
            .await
            .map_err(Exchange::after)?;
        keep = false;
    }
    Ok((response, keep))
}

async fn read_chunked(stream: &mut (impl AsyncBufRead + Unpin)) -> Result<Vec<u8>, ClientError> {
    let mut body = Vec::new();
    let mut line = String::new();
    loop {
        line.clear();
        if stream.read_line(&mut line).await? == 0 {
            return Err(malformed("connection closed in a chunked body"));
        }
        let size = line.trim().split(';').next().unwrap_or("");
        let n = usize::from_str_radix(size, 16)
            .map_err(|_| malformed(format!("chunk size {size:?}")))?;
        if n == 0 {
            // Trailers (none expected) up to the empty line.
            loop {
                line.clear();
                if stream.read_line(&mut line).await? == 0 || line.trim_end().is_empty() {
                    return Ok(body);
                }
            }
        }
        let start = body.len();
        body.resize(start + n + 2, 0);
        stream.read_exact(&mut body[start..]).await?;
        body.truncate(start + n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tokio::net::TcpListener;

    /// A one-shot server that answers every connection with `answer` after reading the head.
    async fn serve(answer: &'static [u8]) -> String {
        let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
        let addr = listener.local_addr().expect("addr").to_string();
        tokio::spawn(async move {
            while let Ok((stream, _)) = listener.accept().await {
                let mut stream = BufReader::new(stream);
                let mut line = String::new();
                while stream.read_line(&mut line).await.is_ok_and(|n| n > 0) {
                    if line == "\r\n" {
                        break;
                    }
                    line.clear();
                }
                let _ = stream.get_mut().write_all(answer).await;
            }
        });
        addr
    }

    #[tokio::test]
    async fn reads_length_chunked_and_to_close_bodies() {
        let addr = serve(b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\nX-A: b\r\n\r\nhello").await;
        let r = Client::new(&addr)
            .send(&Request::get("/"))
            .await
            .expect("r");
        assert_eq!(
            (r.status, r.text().as_str(), r.header("x-a")),
            (200, "hello", Some("b"))
        );

        let addr = serve(
            b"HTTP/1.1 201 Created\r\nTransfer-Encoding: chunked\r\n\r\n3\r\nabc\r\n2;x=y\r\nde\r\n0\r\n\r\n",
        )
        .await;
        let r = Client::new(&addr)
            .send(&Request::get("/"))
            .await
            .expect("r");
        assert_eq!((r.status, r.text().as_str()), (201, "abcde"));

        let addr = serve(b"HTTP/1.1 404 Not Found\r\nConnection: close\r\n\r\ngone").await;
        let r = Conn::new(&addr).send(&Request::get("/")).await.expect("r");
        assert_eq!((r.status, r.text().as_str()), (404, "gone"));
    }

    #[test]
    fn json_sets_the_content_type_once_and_encodes_the_length() {
        let r = Request::post("/v1/jobs").bearer("t").json("{}");
        let wire = String::from_utf8(r.encode("h:1", true)).expect("utf8");
        assert_eq!(
            wire,
            "POST /v1/jobs HTTP/1.1\r\nHost: h:1\r\nAuthorization: Bearer t\r\n\
             Content-Type: application/json\r\nContent-Length: 2\r\nConnection: close\r\n\r\n{}"
        );
        let typed = Request::post("/")
            .header("Content-Type", "text/csv")
            .json("a");
        assert_eq!(typed.headers.len(), 1);
        assert_eq!(host_port("http://127.0.0.1:9/x"), "127.0.0.1:9");
    }
}
