//! A robot's recorded log on a page (`host view --log`): the caller checks
//! the log frame by frame (the view knows no log format) and hands over the
//! result as one JSON document with the field image; `recording.html`
//! fetches both and plays the frames on a timeline.
//!
//! Served: `/` (the page), `/recording.json` (the document), `/field.png`;
//! nothing else, GET only, loopback unless the caller binds elsewhere.

use crate::http::{self, Connection, Connections};
use std::net::{SocketAddr, TcpListener};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The page, built in.
const PAGE: &str = include_str!("recording.html");

const JSON: &str = "application/json";

/// What the page is served.
struct Served {
    document: Vec<u8>,
    field_png: Vec<u8>,
}

/// A recorded log served to browsers.
pub struct RecordingView {
    listener: TcpListener,
    address: SocketAddr,
    served: Arc<Served>,
    open: Arc<Connections>,
}

impl RecordingView {
    /// Listens on `bind` (port 0: any free one) to serve `document` (the
    /// checked log, JSON) and `field_png`; errors name the address.
    pub fn listen(
        bind: SocketAddr,
        document: Vec<u8>,
        field_png: Vec<u8>,
    ) -> Result<RecordingView, String> {
        let listener = http::bind_listener(bind)?;
        let address = listener
            .local_addr()
            .map_err(|e| format!("cannot read the address of {bind}: {e}"))?;
        Ok(RecordingView {
            listener,
            address,
            served: Arc::new(Served {
                document,
                field_png,
            }),
            open: Arc::new(Connections::new(address)),
        })
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }

    /// Answers connections until the process ends, each in its own thread.
    pub fn serve(&self) {
        let served = self.served.clone();
        http::serve_connections(
            &self.listener,
            &self.open,
            &AtomicBool::new(false),
            move |connection| served.connection(connection),
        );
    }

    /// Serves from a background thread (the caller goes on: a test).
    pub fn spawn(self) -> Result<SocketAddr, String> {
        let address = self.address;
        http::spawn_server(move || self.serve())?;
        Ok(address)
    }
}

impl Served {
    /// One connection: one request, answered.
    fn connection(&self, mut connection: Connection) {
        let Some(request) = http::accept_request(&mut connection, 0) else {
            return;
        };
        let stream = &mut connection.stream;
        let get = matches!(request.method.as_str(), "GET" | "HEAD");
        let (status, kind, body): (u16, &str, &[u8]) = match (request.path.as_str(), get) {
            ("/" | "/index.html", true) => (200, "text/html; charset=utf-8", PAGE.as_bytes()),
            ("/recording.json", true) => (200, JSON, &self.document),
            ("/field.png", true) => (200, "image/png", &self.field_png),
            ("/" | "/index.html" | "/recording.json" | "/field.png", false) => {
                let message = format!("{} is not served at {}", request.method, request.path);
                return http::respond(stream, 405, JSON, &http::error_json(&message));
            }
            (path, _) => {
                let message = format!(
                    "not found: {path} (this server has /, /recording.json and /field.png)"
                );
                return http::respond(stream, 404, JSON, &http::error_json(&message));
            }
        };
        http::reply(stream, &request, status, kind, body);
    }
}
