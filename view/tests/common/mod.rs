//! A view served in the test's process, and plain requests to it.

#![allow(dead_code, reason = "each test binary uses part of the helper")]

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use view::{Speed, View, ViewOptions, ViewSettings};

/// Serves `settings` on a free loopback port; its address.
pub fn serve(settings: ViewSettings, paused: bool, speed: Speed) -> SocketAddr {
    let options = ViewOptions {
        bind: "127.0.0.1:0".parse().unwrap(),
        settings,
        policies: Some(concat!(env!("CARGO_MANIFEST_DIR"), "/../policies").into()),
        allowed: Default::default(),
        paused,
        speed,
    };
    View::start(options).unwrap().spawn().unwrap()
}

/// A small world: 5 robots, 40 pucks.
pub fn small(seed: u64) -> ViewSettings {
    let mut settings = ViewSettings::default();
    settings.world.robots = Some(5);
    settings.world.pucks = Some(40);
    settings.world.seed = seed;
    settings
}

/// One request; the status and body.
pub fn request(address: SocketAddr, method: &str, path: &str, body: &[u8]) -> (u16, String) {
    let mut stream = TcpStream::connect(address).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: {address}\r\nContent-Length: {}\r\n\r\n",
        body.len()
    )
    .unwrap();
    stream.write_all(body).unwrap();
    let mut reply = Vec::new();
    stream.read_to_end(&mut reply).unwrap();
    let reply = String::from_utf8_lossy(&reply).to_string();
    let (head, body) = reply.split_once("\r\n\r\n").unwrap_or((&reply, ""));
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    (status, body.to_string())
}

/// The current state: hello and frame.
pub fn state(address: SocketAddr) -> serde_json::Value {
    let (status, body) = request(address, "GET", "/state.json", b"");
    assert_eq!(status, 200, "{body}");
    serde_json::from_str(&body).unwrap()
}

/// Waits until the frame's step is `step`.
pub fn wait_for_step(address: SocketAddr, step: u64) -> serde_json::Value {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    loop {
        let s = state(address);
        if s["frame"]["step"] == step {
            return s;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "step {} not {step}",
            s["frame"]["step"]
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Sends `bytes` as they are and reads the answer until the server closes
/// or 20 s have passed; empty when none came.
pub fn raw(address: SocketAddr, bytes: &[u8]) -> String {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let mut stream = TcpStream::connect(address).unwrap();
    let _ = stream.write_all(bytes);
    let mut reply = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            break;
        }
        match stream.read(&mut chunk) {
            Ok(0) | Err(_) => break,
            Ok(n) => reply.extend_from_slice(&chunk[..n]),
        }
    }
    String::from_utf8_lossy(&reply).to_string()
}
