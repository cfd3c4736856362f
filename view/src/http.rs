//! Just enough HTTP/1.1 for the view's servers, written here so every
//! socket is ours to bound: connections accepted each on its own thread,
//! at most [`MAX_CONNECTIONS`] at once and [`MAX_PER_CLIENT`] from one
//! address; one request a connection (the answer closes it), read whole
//! within [`REQUEST_DEADLINE`], its head at most [`HEAD_LIMIT`] bytes, a
//! body of at most the caller's limit with one `Content-Length` (no
//! `Transfer-Encoding`); every write with a timeout; HEAD answered without
//! the body; errors answered as JSON; and the WebSocket handshake.
//!
//! Only the page's own requests are obeyed: the `Host` header must name the
//! server by address (`localhost`, a loopback address, or the address it is
//! bound to; any port, so tunnels work), which a DNS-rebinding page's name
//! does not; and a state-changing request (any method but GET and HEAD)
//! or a WebSocket upgrade that carries an `Origin` must come from
//! `http://` and that same host. A request without `Origin` (curl, a
//! script) is not a browser's cross-site request and is served.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{IpAddr, Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Longest request head.
pub const HEAD_LIMIT: usize = 16 * 1024;

/// How long a write may wait.
pub const TIMEOUT: Duration = Duration::from_secs(10);

/// How long a whole request (head and body) may take to arrive.
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(10);

/// Connections served at once.
pub const MAX_CONNECTIONS: usize = 512;

/// Connections served at once from one address.
pub const MAX_PER_CLIENT: usize = 256;

/// A connection still sending its request after this long may be closed
/// to make room for a new one when the limits are reached.
pub const EVICT_AFTER: Duration = Duration::from_secs(1);

/// Binds `bind`, warning on stderr when it is not a loopback address
/// (every machine that reaches this one may then watch and drive the
/// view); errors name the address.
pub fn bind_listener(bind: SocketAddr) -> Result<TcpListener, String> {
    let listener = TcpListener::bind(bind).map_err(|e| format!("cannot listen on {bind}: {e}"))?;
    if let Some(warning) = exposure_warning(listener.local_addr().unwrap_or(bind)) {
        eprintln!("warning: {warning}");
    }
    Ok(listener)
}

/// The warning for serving on `bind`, or `None` on a loopback address.
fn exposure_warning(bind: SocketAddr) -> Option<String> {
    (!bind.ip().is_loopback()).then(|| {
        format!(
            "serving on {bind}, not loopback: every machine that can reach this one can open the page and drive it"
        )
    })
}

/// The open connections of one server: how many, from where, and which
/// are still sending their request (those may be closed to make room).
#[derive(Debug)]
pub struct Connections {
    bound: IpAddr,
    open: Mutex<Open>,
}

#[derive(Debug, Default)]
struct Open {
    next: u64,
    /// By ticket: the peer, when it connected, and while its request is
    /// being read a handle to close it by.
    entries: BTreeMap<u64, Entry>,
}

#[derive(Debug)]
struct Entry {
    peer: IpAddr,
    since: Instant,
    reading: Option<TcpStream>,
}

impl Connections {
    /// None yet, for a server bound to `bound`.
    pub fn new(bound: SocketAddr) -> Connections {
        Connections {
            bound: bound.ip(),
            open: Mutex::new(Open::default()),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Open> {
        // the table is valid whatever a panicking holder did
        self.open
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Admits `stream` from `peer`, closing the oldest connection still
    /// sending its request (for at least [`EVICT_AFTER`]) when a limit is
    /// reached; `None` when there is none to close.
    fn admit(self: &Arc<Self>, stream: &TcpStream, peer: IpAddr) -> Option<Ticket> {
        let now = Instant::now();
        let mut open = self.lock();
        let mine = open.entries.values().filter(|e| e.peer == peer).count();
        let full = open.entries.len() >= MAX_CONNECTIONS;
        if mine >= MAX_PER_CLIENT || full {
            let victim = open
                .entries
                .iter()
                .filter(|(_, e)| {
                    e.reading.is_some()
                        && now.duration_since(e.since) >= EVICT_AFTER
                        && (mine < MAX_PER_CLIENT || e.peer == peer)
                })
                .min_by_key(|(_, e)| e.since)
                .map(|(k, _)| *k)?;
            if let Some(old) = open.entries.remove(&victim).and_then(|e| e.reading) {
                let _ = old.shutdown(Shutdown::Both);
            }
        }
        let id = open.next;
        open.next += 1;
        open.entries.insert(
            id,
            Entry {
                peer,
                since: now,
                reading: stream.try_clone().ok(),
            },
        );
        Some(Ticket {
            connections: self.clone(),
            id,
            since: now,
        })
    }
}

/// A connection's place among the open ones, given up when dropped.
#[derive(Debug)]
struct Ticket {
    connections: Arc<Connections>,
    id: u64,
    since: Instant,
}

impl Ticket {
    /// Its request is read: it may no longer be closed to make room.
    fn read(&self) {
        if let Some(e) = self.connections.lock().entries.get_mut(&self.id) {
            e.reading = None;
        }
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        self.connections.lock().entries.remove(&self.id);
    }
}

/// An accepted connection: its socket, and its place among the open ones
/// (held until this is dropped).
#[derive(Debug)]
pub struct Connection {
    /// The socket.
    pub stream: TcpStream,
    ticket: Ticket,
}

/// Answers connections on `listener`, each in its own thread running
/// `answer`, within the limits `connections` keeps (the rest get 503),
/// until a connection arrives after `stopped` is set.
pub fn serve_connections<F>(
    listener: &TcpListener,
    connections: &Arc<Connections>,
    stopped: &AtomicBool,
    answer: F,
) where
    F: Fn(Connection) + Clone + Send + 'static,
{
    for stream in listener.incoming() {
        if stopped.load(Ordering::SeqCst) {
            return;
        }
        let Ok(mut stream) = stream else { continue };
        let Ok(peer) = stream.peer_addr() else {
            continue;
        };
        let Some(ticket) = connections.admit(&stream, peer.ip()) else {
            let _ = stream.set_write_timeout(Some(Duration::from_secs(1)));
            respond(&mut stream, 503, "text/plain", b"too many connections\n");
            continue;
        };
        let answer = answer.clone();
        // a thread that cannot start drops the connection and its ticket
        let _ = std::thread::Builder::new()
            .name("view-conn".into())
            .spawn(move || answer(Connection { stream, ticket }));
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
    /// A header's value (the first, if it is repeated).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Whether it asks for a WebSocket.
    pub fn is_websocket(&self) -> bool {
        self.header("upgrade")
            .is_some_and(|v| v.trim().eq_ignore_ascii_case("websocket"))
    }

    /// Whether it is a HEAD request (answered without the body).
    pub fn is_head(&self) -> bool {
        self.method == "HEAD"
    }

    /// The body's length its headers give: 0 without `Content-Length`;
    /// refused when the lengths given differ or a `Transfer-Encoding` is
    /// given (this server reads no chunked bodies).
    fn content_length(&self) -> Result<usize, BadRequest> {
        if self.header("transfer-encoding").is_some() {
            return Err(bad(
                400,
                "Transfer-Encoding is not accepted: send the body with a Content-Length",
            ));
        }
        let mut lengths = self
            .headers
            .iter()
            .filter(|(n, _)| n == "content-length")
            .map(|(_, v)| {
                v.trim()
                    .parse::<usize>()
                    .map_err(|_| bad(400, format!("Content-Length {v:?}: not a whole number")))
            });
        let first = lengths.next().transpose()?.unwrap_or(0);
        for other in lengths {
            if other? != first {
                return Err(bad(
                    400,
                    "Content-Length is given twice, with different values",
                ));
            }
        }
        Ok(first)
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

/// Reads from `stream` into `buf` before `deadline`: the bytes read (0 at
/// the end), 408 when the deadline passes.
fn read_before(
    stream: &mut TcpStream,
    buf: &mut [u8],
    deadline: Instant,
) -> Result<usize, BadRequest> {
    let late = || {
        bad(
            408,
            format!(
                "the request did not arrive within {} s",
                REQUEST_DEADLINE.as_secs()
            ),
        )
    };
    let left = deadline.saturating_duration_since(Instant::now());
    if left.is_zero() {
        return Err(late());
    }
    let _ = stream.set_read_timeout(Some(left));
    match stream.read(buf) {
        Ok(n) => Ok(n),
        Err(_) if Instant::now() >= deadline => Err(late()),
        Err(e) => Err(BadRequest {
            status: None,
            message: e.to_string(),
        }),
    }
}

/// Reads one request, whole by `deadline`; a body longer than
/// `body_limit` is refused (413).
pub fn read_request(
    stream: &mut TcpStream,
    body_limit: usize,
    deadline: Instant,
) -> Result<Request, BadRequest> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 4096];
    let head_end = loop {
        if let Some(end) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break end + 4;
        }
        if buf.len() > HEAD_LIMIT {
            return Err(bad(431, "request head too long"));
        }
        let n = read_before(stream, &mut chunk, deadline)?;
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
    let length = request.content_length()?;
    if length > body_limit {
        return Err(bad(
            413,
            format!("the body is {length} bytes, more than the {body_limit} allowed"),
        ));
    }
    while request.body.len() < length {
        let n = read_before(stream, &mut chunk, deadline)?;
        if n == 0 {
            return Err(bad(400, "the body ended early"));
        }
        request.body.extend_from_slice(&chunk[..n]);
    }
    request.body.truncate(length);
    Ok(request)
}

/// The host part of a `Host` header or an origin's authority: an address
/// or a name, without the port and brackets, in lower case.
fn host_name(authority: &str) -> String {
    let authority = authority.trim();
    let name = match authority.strip_prefix('[') {
        Some(rest) => rest.split(']').next().unwrap_or(""),
        None => match authority.rsplit_once(':') {
            Some((name, port)) if port.bytes().all(|b| b.is_ascii_digit()) => name,
            _ => authority,
        },
    };
    name.to_ascii_lowercase()
}

/// Whether a `Host` header names a server bound to `bound`: `localhost`, a
/// loopback address, or (any address when bound to all) the bound one.
fn host_allowed(host: &str, bound: IpAddr) -> bool {
    let name = host_name(host);
    if name == "localhost" {
        return true;
    }
    match name.parse::<IpAddr>() {
        Ok(ip) => ip.is_loopback() || bound.is_unspecified() || ip == bound,
        Err(_) => false,
    }
}

/// Refuses (403) what the page did not send: a `Host` other than this
/// server's address; a state-changing request or WebSocket upgrade whose
/// `Origin` is another site's.
fn check_origin(request: &Request, bound: IpAddr) -> Result<(), BadRequest> {
    let host = request.header("host");
    if let Some(host) = host {
        if !host_allowed(host, bound) {
            return Err(bad(
                403,
                format!("Host {host:?}: this server answers only to its address (localhost or an IP address)"),
            ));
        }
    }
    let changes = !matches!(request.method.as_str(), "GET" | "HEAD") || request.is_websocket();
    let Some(origin) = request.header("origin").filter(|_| changes) else {
        return Ok(());
    };
    let own = match (origin.trim().strip_prefix("http://"), host) {
        (Some(authority), Some(host)) => authority.eq_ignore_ascii_case(host.trim()),
        (Some(authority), None) => host_allowed(authority, bound),
        (None, _) => false,
    };
    if own {
        Ok(())
    } else {
        Err(bad(
            403,
            format!("Origin {origin:?}: only this server's own page may change it"),
        ))
    }
}

/// A connection's request, read whole within [`REQUEST_DEADLINE`] of its
/// arrival and checked for its `Host` and `Origin`; a request that cannot
/// be read or is refused is answered (its status, the message as
/// [`error_json`]) and gives `None`.
pub fn accept_request(connection: &mut Connection, body_limit: usize) -> Option<Request> {
    let stream = &mut connection.stream;
    let _ = stream.set_write_timeout(Some(TIMEOUT));
    let deadline = connection.ticket.since + REQUEST_DEADLINE;
    let read = read_request(stream, body_limit, deadline)
        .and_then(|r| check_origin(&r, connection.ticket.connections.bound).map(|()| r));
    connection.ticket.read();
    match read {
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

/// Answers `request` and closes: `status`, `kind` (Content-Type) and
/// `body`, the body left out for HEAD.
pub fn reply(stream: &mut TcpStream, request: &Request, status: u16, kind: &str, body: &[u8]) {
    write_answer(
        stream,
        status,
        kind,
        body.len(),
        if request.is_head() { &[] } else { body },
    );
}

/// Answers and closes: `status`, `kind` (Content-Type) and `body`.
pub fn respond(stream: &mut TcpStream, status: u16, kind: &str, body: &[u8]) {
    write_answer(stream, status, kind, body.len(), body);
}

fn write_answer(stream: &mut TcpStream, status: u16, kind: &str, length: usize, body: &[u8]) {
    let reason = match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        413 => "Payload Too Large",
        426 => "Upgrade Required",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Error",
    };
    let head = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {kind}\r\nContent-Length: {length}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n"
    );
    // a client that went away needs no answer
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .and_then(|()| stream.flush());
}

/// Whether `key` is a `Sec-WebSocket-Key`: 16 bytes in base64 (24
/// characters, the last two `==`).
fn websocket_key(key: &str) -> bool {
    let key = key.as_bytes();
    key.len() == 24
        && key.ends_with(b"==")
        && key[..22]
            .iter()
            .all(|b| b.is_ascii_alphanumeric() || *b == b'+' || *b == b'/')
}

/// Answers a WebSocket request with the handshake (101) and gives
/// `true`; refuses one that is not a version 13 upgrade by GET with a key
/// (400, or 426 for another version) and gives `false`, as it does when
/// the client went away.
pub fn accept_websocket(stream: &mut TcpStream, request: &Request) -> bool {
    let key = request.header("sec-websocket-key").unwrap_or("").trim();
    let refusal = if request.method != "GET" {
        Some((400, "a WebSocket is opened with GET"))
    } else if !websocket_key(key) {
        Some((
            400,
            "a WebSocket upgrade needs a Sec-WebSocket-Key of 16 bytes in base64",
        ))
    } else if request.header("sec-websocket-version").map(str::trim) != Some("13") {
        Some((
            426,
            "this server speaks WebSocket version 13 (Sec-WebSocket-Version: 13)",
        ))
    } else {
        None
    };
    if let Some((status, message)) = refusal {
        respond(stream, status, "application/json", &error_json(message));
        return false;
    }
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    write!(
        stream,
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    )
    .and_then(|()| stream.flush())
    .is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_host_must_name_the_server_by_address() {
        let loopback: IpAddr = "127.0.0.1".parse().unwrap();
        let all: IpAddr = "0.0.0.0".parse().unwrap();
        for host in [
            "127.0.0.1:8076",
            "localhost:8076",
            "LOCALHOST",
            "[::1]:9000",
            "127.0.0.1",
        ] {
            assert!(host_allowed(host, loopback), "{host}");
        }
        for host in [
            "evil.example",
            "evil.example:8076",
            "192.168.1.5:8076",
            "127.0.0.1.evil.example",
            "",
        ] {
            assert!(!host_allowed(host, loopback), "{host}");
        }
        assert!(host_allowed("192.168.1.5:8076", all));
        assert!(!host_allowed("myhost.lan:8076", all));
    }

    #[test]
    fn only_a_bind_off_loopback_is_warned_of() {
        assert!(exposure_warning("127.0.0.1:8076".parse().unwrap()).is_none());
        assert!(exposure_warning("[::1]:8076".parse().unwrap()).is_none());
        let warning = exposure_warning("0.0.0.0:8076".parse().unwrap()).unwrap();
        assert!(warning.contains("0.0.0.0:8076"), "{warning}");
    }
}
