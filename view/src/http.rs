//! Just enough HTTP/1.1 for the view's servers: connections accepted each
//! on its own thread, at most [`MAX_CONNECTIONS`] at once; one request a
//! connection (the answer closes it), headers at most [`HEAD_LIMIT`] bytes,
//! a body of at most the caller's limit, every read and write with a
//! timeout (so a half-open connection ends), errors answered as JSON; and
//! the WebSocket handshake.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Longest request head.
pub const HEAD_LIMIT: usize = 16 * 1024;

/// How long a read or a write may wait.
pub const TIMEOUT: Duration = Duration::from_secs(10);

/// Connections served at once; more are answered 503.
pub const MAX_CONNECTIONS: usize = 512;

/// Answers connections on `listener`, each in its own thread running
/// `answer`, at most [`MAX_CONNECTIONS`] at once (`open` counts them; the
/// rest get 503), until a connection arrives after `stopped` is set.
pub fn serve_connections<F>(
    listener: &TcpListener,
    open: &Arc<AtomicUsize>,
    stopped: &AtomicBool,
    answer: F,
) where
    F: Fn(TcpStream) + Clone + Send + 'static,
{
    for stream in listener.incoming() {
        if stopped.load(Ordering::SeqCst) {
            return;
        }
        let Ok(mut stream) = stream else { continue };
        if open.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            open.fetch_sub(1, Ordering::SeqCst);
            let _ = stream.set_write_timeout(Some(Duration::from_secs(1)));
            respond(&mut stream, 503, "text/plain", b"too many connections\n");
            continue;
        }
        let (answer, counted) = (answer.clone(), open.clone());
        let spawned = std::thread::Builder::new()
            .name("view-conn".into())
            .spawn(move || {
                answer(stream);
                counted.fetch_sub(1, Ordering::SeqCst);
            });
        if spawned.is_err() {
            open.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

/// A request.
#[derive(Debug)]
pub struct Request {
    /// GET, POST, ...
    pub method: String,
    /// The path, without the query.
    pub path: String,
    /// The query, without `?`.
    pub query: String,
    /// Headers, names in lower case.
    pub headers: Vec<(String, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Request {
    /// A header's value.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Whether it asks for a WebSocket.
    pub fn is_websocket(&self) -> bool {
        self.header("upgrade")
            .is_some_and(|v| v.eq_ignore_ascii_case("websocket"))
    }
}

/// Why a request could not be read; the status to answer with, if any.
#[derive(Debug)]
pub struct BadRequest {
    /// The status to answer (none when the connection is gone).
    pub status: Option<u16>,
    /// What was wrong.
    pub message: String,
}

fn bad(status: u16, message: impl Into<String>) -> BadRequest {
    BadRequest {
        status: Some(status),
        message: message.into(),
    }
}

/// Reads one request; a body longer than `body_limit` is refused (413).
pub fn read_request(stream: &mut TcpStream, body_limit: usize) -> Result<Request, BadRequest> {
    let gone = |e: std::io::Error| BadRequest {
        status: None,
        message: e.to_string(),
    };
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 4096];
    let head_end = loop {
        if let Some(end) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break end + 4;
        }
        if buf.len() > HEAD_LIMIT {
            return Err(bad(431, "request head too long"));
        }
        let n = stream.read(&mut chunk).map_err(gone)?;
        if n == 0 {
            return Err(BadRequest {
                status: None,
                message: "closed".into(),
            });
        }
        buf.extend_from_slice(&chunk[..n]);
    };
    let mut headers = [httparse::EMPTY_HEADER; 64];
    let mut parsed = httparse::Request::new(&mut headers);
    match parsed.parse(&buf[..head_end]) {
        Ok(httparse::Status::Complete(_)) => {}
        _ => return Err(bad(400, "malformed request")),
    }
    let target = parsed.path.unwrap_or("/");
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let request_headers: Vec<(String, String)> = parsed
        .headers
        .iter()
        .map(|h| {
            (
                h.name.to_ascii_lowercase(),
                String::from_utf8_lossy(h.value).into_owned(),
            )
        })
        .collect();
    let mut request = Request {
        method: parsed.method.unwrap_or("").to_string(),
        path: path.to_string(),
        query: query.split('#').next().unwrap_or("").to_string(),
        headers: request_headers,
        body: buf[head_end..].to_vec(),
    };
    let length = match request.header("content-length") {
        None => 0,
        Some(v) => v
            .trim()
            .parse::<usize>()
            .map_err(|_| bad(400, "bad Content-Length"))?,
    };
    if length > body_limit {
        return Err(bad(
            413,
            format!("the body is {length} bytes, more than the {body_limit} allowed"),
        ));
    }
    while request.body.len() < length {
        let n = stream.read(&mut chunk).map_err(gone)?;
        if n == 0 {
            return Err(bad(400, "the body ended early"));
        }
        request.body.extend_from_slice(&chunk[..n]);
    }
    request.body.truncate(length);
    Ok(request)
}

/// A connection's request, with [`TIMEOUT`] on its reads and writes; a
/// request that cannot be read is answered (its status, the message as
/// [`error_json`]) and gives `None`.
pub fn accept_request(stream: &mut TcpStream, body_limit: usize) -> Option<Request> {
    let _ = stream.set_read_timeout(Some(TIMEOUT));
    let _ = stream.set_write_timeout(Some(TIMEOUT));
    match read_request(stream, body_limit) {
        Ok(r) => Some(r),
        Err(e) => {
            if let Some(status) = e.status {
                respond(stream, status, "application/json", &error_json(&e.message));
            }
            None
        }
    }
}

/// `{"error": message}`, the view's error answers.
pub fn error_json(message: &str) -> Vec<u8> {
    serde_json::json!({ "error": message })
        .to_string()
        .into_bytes()
}

/// Runs `serve` on a thread of its own (a server's accepting loop).
pub fn spawn_server(serve: impl FnOnce() + Send + 'static) -> Result<(), String> {
    std::thread::Builder::new()
        .name("view-accept".into())
        .spawn(serve)
        .map(drop)
        .map_err(|e| format!("cannot start the server's thread: {e}"))
}

/// Answers and closes: `status`, `kind` (Content-Type) and `body`.
pub fn respond(stream: &mut TcpStream, status: u16, kind: &str, body: &[u8]) {
    let reason = match status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Payload Too Large",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Error",
    };
    let head = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    // a client that went away needs no answer
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .and_then(|()| stream.flush());
}

/// Answers a WebSocket request with the handshake (101).
pub fn accept_websocket(stream: &mut TcpStream, request: &Request) -> std::io::Result<()> {
    let key = request.header("sec-websocket-key").unwrap_or("");
    let accept = tungstenite::handshake::derive_accept_key(key.trim().as_bytes());
    write!(
        stream,
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    )?;
    stream.flush()
}
