//! The tests' and the bench's HTTP client: requests to the service's own API on `reqwest`
//! (plain HTTP/1.1, no TLS, no proxy, no redirects, no compression: the service sends none).
//!
//! [`Client::new`] opens a connection per request, so it never holds an idle connection that a
//! graceful shutdown would wait for (the tests); [`Client::keep_alive`] keeps one connection
//! and reuses it, so a task that sends its requests one after another holds exactly one (the
//! load benchmark: one client per task).

use std::time::Duration;

/// How long one request may take, connect to last body byte, unless set otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(60);

#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    #[error("HTTP: {0}")]
    Http(#[from] reqwest::Error),
    #[error("bad request for the client: {0}")]
    Request(String),
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
        let typed = self
            .headers
            .iter()
            .any(|(k, _)| k.eq_ignore_ascii_case("content-type"));
        let r = self.body(body);
        if typed {
            r
        } else {
            r.header("Content-Type", "application/json")
        }
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

/// `http://host:port` of an address given as `http://host:port[/...]` or `host:port`.
fn base_url(addr: &str) -> String {
    let rest = addr.strip_prefix("http://").unwrap_or(addr);
    format!("http://{}", rest.split('/').next().unwrap_or(rest))
}

/// A client of one server. Cheap to clone (clones share the connection pool); use it on the
/// tokio runtime it first sent on.
#[derive(Debug, Clone)]
pub struct Client {
    base: String,
    http: reqwest::Client,
}

impl Client {
    /// A client of the server at `addr` (`127.0.0.1:8080` or `http://127.0.0.1:8080`) that
    /// opens a connection per request.
    pub fn new(addr: &str) -> Result<Self, ClientError> {
        Self::build(addr, 0, DEFAULT_TIMEOUT)
    }

    /// A client that keeps one idle connection and reuses it.
    pub fn keep_alive(addr: &str) -> Result<Self, ClientError> {
        Self::build(addr, 1, DEFAULT_TIMEOUT)
    }

    /// [`Client::new`] with another time limit per request.
    pub fn with_timeout(addr: &str, timeout: Duration) -> Result<Self, ClientError> {
        Self::build(addr, 0, timeout)
    }

    fn build(addr: &str, idle: usize, timeout: Duration) -> Result<Self, ClientError> {
        let http = reqwest::Client::builder()
            .no_proxy()
            .redirect(reqwest::redirect::Policy::none())
            .pool_max_idle_per_host(idle)
            .tcp_nodelay(true)
            .timeout(timeout)
            .build()?;
        Ok(Client {
            base: base_url(addr),
            http,
        })
    }

    /// `http://host:port` of the server.
    pub fn base(&self) -> &str {
        &self.base
    }

    pub async fn send(&self, request: &Request) -> Result<Response, ClientError> {
        let method = reqwest::Method::from_bytes(request.method.as_bytes())
            .map_err(|_| ClientError::Request(format!("method {:?}", request.method)))?;
        let mut builder = self
            .http
            .request(method, format!("{}{}", self.base, request.path));
        for (k, v) in &request.headers {
            builder = builder.header(k.as_str(), v.as_str());
        }
        if let Some(body) = &request.body {
            builder = builder.body(body.clone());
        }
        let response = builder.send().await?;
        let status = response.status().as_u16();
        let headers = response
            .headers()
            .iter()
            .map(|(k, v)| {
                let value = String::from_utf8_lossy(v.as_bytes()).into_owned();
                (k.as_str().to_string(), value)
            })
            .collect();
        let body = response.bytes().await?.to_vec();
        Ok(Response {
            status,
            headers,
            body,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_sets_the_content_type_once() {
        let r = Request::post("/v1/jobs").bearer("t").json("{}");
        assert_eq!(
            r.headers,
            [
                ("Authorization".to_string(), "Bearer t".to_string()),
                ("Content-Type".to_string(), "application/json".to_string())
            ]
        );
        let typed = Request::post("/")
            .header("Content-Type", "text/csv")
            .json("a");
        assert_eq!(typed.headers.len(), 1);
        assert_eq!(base_url("http://127.0.0.1:9/x"), "http://127.0.0.1:9");
        assert_eq!(base_url("127.0.0.1:9"), "http://127.0.0.1:9");
    }
}
