//! A `host view` process for the CLI tests (started on a free port, its
//! address read from its first line, stopped when dropped), and one request
//! to it or to any page `host` serves.

#![allow(dead_code, reason = "each test binary uses part of the helper")]

use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

/// A running `host view`.
pub struct Served {
    child: Child,
    /// Where it listens, `IP:PORT`.
    pub address: String,
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `host view --port 0 ARGS`.
pub fn serve<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Served {
    let mut child = Command::new(env!("CARGO_BIN_EXE_host"))
        .args(["view", "--port", "0"])
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .expect("cannot start host view");
    let mut first = String::new();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    stdout.read_line(&mut first).unwrap();
    let address = first
        .trim()
        .strip_prefix("view: serving http://")
        .unwrap_or_else(|| panic!("first line: {first:?}"))
        .trim_end_matches('/')
        .to_string();
    // kept reading: what it prints next must find an open pipe, or SIGPIPE ends it
    std::thread::spawn(move || std::io::copy(&mut stdout, &mut std::io::sink()));
    Served { child, address }
}

/// The status and body of `METHOD PATH` (with an empty body).
pub fn request(address: &str, method: &str, path: &str) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(address).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: {address}\r\nContent-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut reply = Vec::new();
    stream.read_to_end(&mut reply).unwrap();
    let end = reply.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&reply[..end]).to_string();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    (status, reply[end + 4..].to_vec())
}
