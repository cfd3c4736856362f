//! Headless Chromium (Debian's `chromium`, which `scripts/setup` installs)
//! driven over the DevTools protocol: a page that keeps running in real
//! time (the display tests' `--dump-dom` with virtual time suits a still
//! page, not a live stream), its state read with `Runtime.evaluate`.
//! `host/tests/display_cli.rs` takes [`chromium`] from here too.

#![allow(dead_code, reason = "each test binary uses part of the helper")]

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::{Message, WebSocket};

/// Headless Chromium, or a failure saying what to install.
pub fn chromium() -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|dir| dir.join("chromium"))
        .find(|p| p.is_file())
        .expect(
            "the browser tests need headless Chromium: apt-get install chromium (scripts/setup installs it)",
        )
}

/// A headless Chromium showing one page, ended when dropped.
pub struct Browser {
    child: Child,
    _profile: tempfile::TempDir,
    socket: WebSocket<TcpStream>,
    next_id: u64,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn http_get(port: u16, path: &str) -> String {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    // Chromium keeps the connection open: read the head, then its Content-Length
    let mut reply = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        let n = stream.read(&mut chunk).unwrap_or(0);
        reply.extend_from_slice(&chunk[..n]);
        let text = String::from_utf8_lossy(&reply).to_string();
        if let Some((head, body)) = text.split_once("\r\n\r\n") {
            let length = head
                .lines()
                .find_map(|l| {
                    l.to_ascii_lowercase()
                        .strip_prefix("content-length:")
                        .map(|v| v.trim().parse::<usize>().unwrap_or(0))
                })
                .unwrap_or(0);
            if body.len() >= length || n == 0 {
                return body.to_string();
            }
        } else if n == 0 {
            return String::new();
        }
    }
}

impl Browser {
    /// Opens `url` in a `width` x `height` window.
    pub fn open(url: &str, (width, height): (u32, u32)) -> Browser {
        let profile = tempfile::tempdir().unwrap();
        let child = Command::new(chromium())
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--hide-scrollbars",
                "--force-device-scale-factor=1",
                "--remote-debugging-port=0",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg(format!("--window-size={width},{height}"))
            .arg(url)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start chromium");
        // Chromium writes the port it chose into the profile.
        let deadline = Instant::now() + Duration::from_secs(60);
        let port_file = profile.path().join("DevToolsActivePort");
        let port: u16 = loop {
            if let Some(port) = std::fs::read_to_string(&port_file)
                .ok()
                .and_then(|t| t.lines().next()?.trim().parse().ok())
            {
                break port;
            }
            assert!(Instant::now() < deadline, "chromium did not start");
            std::thread::sleep(Duration::from_millis(50));
        };
        let target = loop {
            let list: serde_json::Value =
                serde_json::from_str(&http_get(port, "/json/list")).unwrap_or_default();
            let page = list.as_array().and_then(|l| {
                l.iter()
                    .find(|t| t["type"] == "page")
                    .and_then(|t| t["webSocketDebuggerUrl"].as_str().map(String::from))
            });
            if let Some(page) = page {
                break page;
            }
            assert!(Instant::now() < deadline, "chromium shows no page");
            std::thread::sleep(Duration::from_millis(50));
        };
        let stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
        let (socket, _) = tungstenite::client(target.as_str(), stream).unwrap();
        Browser {
            child,
            _profile: profile,
            socket,
            next_id: 1,
        }
    }

    /// The value of the JavaScript expression `expression` (awaited if a promise).
    pub fn eval(&mut self, expression: &str) -> serde_json::Value {
        let id = self.next_id;
        self.next_id += 1;
        let call = serde_json::json!({
            "id": id,
            "method": "Runtime.evaluate",
            "params": { "expression": expression, "returnByValue": true, "awaitPromise": true }
        });
        self.socket.send(Message::text(call.to_string())).unwrap();
        loop {
            let Message::Text(text) = self.socket.read().unwrap() else {
                continue;
            };
            let reply: serde_json::Value = serde_json::from_str(&text).unwrap();
            if reply["id"] == id {
                assert!(
                    reply["result"]["exceptionDetails"].is_null(),
                    "{expression}: {reply}"
                );
                return reply["result"]["result"]["value"].clone();
            }
        }
    }

    /// An attribute of the page's `<html>` (`data-step` is `step`).
    pub fn data(&mut self, name: &str) -> String {
        self.eval(&format!("document.documentElement.dataset.{name} ?? ''"))
            .as_str()
            .unwrap_or("")
            .to_string()
    }

    /// Waits until `condition` (JavaScript) holds (a page still loading
    /// counts as not yet); fails after `seconds`.
    pub fn wait_for(&mut self, condition: &str, seconds: u64) {
        let deadline = Instant::now() + Duration::from_secs(seconds);
        while self.eval(&format!(
            "(() => {{ try {{ return !!({condition}); }} catch (e) {{ return false; }} }})()"
        )) != serde_json::Value::Bool(true)
        {
            assert!(
                Instant::now() < deadline,
                "waited {seconds} s for {condition}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}
