//! The view's server under a tester's hand: it answers while a long step
//! request runs and a pause or new settings cancel it, it obeys only its
//! own page (foreign `Host` or `Origin`: 403), slow or idle connections do
//! not keep the page from loading, and HEAD, the WebSocket handshake,
//! `Content-Length` and bad setting values are answered as HTTP says.

mod common;

use common::{raw, request, serve, small, state};
use std::io::{BufRead, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use view::Speed;

/// The status of a raw request's answer (0 when none came).
fn status_of(reply: &str) -> u16 {
    reply
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

/// A POST of `path` with the header lines `head` and no body: the
/// answer's status and the answer.
fn post(address: SocketAddr, path: &str, head: &str) -> (u16, String) {
    let reply = raw(
        address,
        format!("POST {path} HTTP/1.1\r\n{head}\r\n\r\n").as_bytes(),
    );
    (status_of(&reply), reply)
}

/// `/state.json`'s step, and how long the answer took.
fn timed_step(address: SocketAddr) -> (u64, Duration) {
    let start = Instant::now();
    let reply = raw(
        address,
        format!("GET /state.json HTTP/1.1\r\nHost: {address}\r\n\r\n").as_bytes(),
    );
    let took = start.elapsed();
    assert_eq!(
        status_of(&reply),
        200,
        "no answer to /state.json: {reply:.200}"
    );
    let body = reply.split_once("\r\n\r\n").map_or("", |(_, b)| b);
    let s: serde_json::Value = serde_json::from_str(body).unwrap();
    (s["frame"]["step"].as_u64().unwrap(), took)
}

#[test]
fn requests_are_answered_while_a_million_steps_run_on_a_large_world_and_a_pause_stops_them() {
    let mut settings = small(11);
    settings.world.robots = Some(1000);
    settings.world.pucks = Some(700);
    let address = serve(settings, true, Speed::Real);
    let (status, body) = request(address, "POST", "/control?action=step&steps=1000000", b"");
    assert_eq!(status, 200, "{body}");
    // generous bounds for a loaded machine: the page's target is 1 s
    let (first, took) = timed_step(address);
    assert!(took < Duration::from_secs(5), "/state.json took {took:?}");
    let start = Instant::now();
    let png = raw(
        address,
        format!("GET /field.png HTTP/1.1\r\nHost: {address}\r\n\r\n").as_bytes(),
    );
    assert_eq!(status_of(&png), 200);
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "/field.png took {:?}",
        start.elapsed()
    );
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let (step, took) = timed_step(address);
        assert!(took < Duration::from_secs(5), "/state.json took {took:?}");
        if step > first {
            break;
        }
        assert!(Instant::now() < deadline, "the step stayed at {first}");
        std::thread::sleep(Duration::from_millis(100));
    }
    let start = Instant::now();
    let (status, body) = request(address, "POST", "/control?action=pause", b"");
    assert_eq!(status, 200, "{body}");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "pause took {:?}",
        start.elapsed()
    );
    let (paused, _) = timed_step(address);
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(
        timed_step(address).0,
        paused,
        "the steps went on after a pause"
    );
}

/// The environment variable that makes the stall test's own binary the
/// stalled server.
const STALL_CHILD: &str = "VIEW_STALL_CHILD";

#[test]
fn after_a_five_second_sigstop_the_simulation_steps_again_within_a_second() {
    if std::env::var_os(STALL_CHILD).is_some() {
        // the child: serve, name the address, live at most 2 minutes
        let address = serve(small(21), false, Speed::Real);
        println!("serving {address}");
        std::thread::sleep(Duration::from_secs(120));
        return;
    }
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "after_a_five_second_sigstop_the_simulation_steps_again_within_a_second",
            "--exact",
            "--nocapture",
        ])
        .env(STALL_CHILD, "1")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = std::io::BufReader::new(child.stdout.take().unwrap());
    let address: SocketAddr = stdout
        .lines()
        .map_while(Result::ok)
        .find_map(|l| l.strip_prefix("serving ").map(|a| a.parse().unwrap()))
        .expect("the child named no address");
    let signal = |name: &str| {
        let status = std::process::Command::new("kill")
            .args([name, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success(), "kill {name}");
    };
    // run 8 s first: the frozen time grew with the time run before a stall
    std::thread::sleep(Duration::from_secs(8));
    let before = state(address)["frame"]["step"].as_u64().unwrap();
    assert!(before > 100, "{before} steps in 8 s at 50 a second");
    signal("-STOP");
    std::thread::sleep(Duration::from_secs(5));
    signal("-CONT");
    let resumed = Instant::now();
    let moved = loop {
        let step = state(address)["frame"]["step"].as_u64().unwrap();
        if step > before + 2 {
            break resumed.elapsed();
        }
        if resumed.elapsed() > Duration::from_secs(20) {
            break resumed.elapsed();
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let _ = child.kill();
    let _ = child.wait();
    // the target is 1 s; a loaded machine gets some slack
    assert!(
        moved < Duration::from_secs(4),
        "the simulation moved again only {moved:?} after the stall"
    );
}

#[test]
fn new_settings_and_a_reset_cancel_the_steps_still_pending() {
    let address = serve(small(12), true, Speed::Real);
    for cancel in ["/settings?seed=13", "/control?action=reset"] {
        let (status, body) = request(address, "POST", "/control?action=step&steps=1000000", b"");
        assert_eq!(status, 200, "{body}");
        std::thread::sleep(Duration::from_millis(200));
        let (running, took) = timed_step(address);
        assert!(took < Duration::from_secs(3), "/state.json took {took:?}");
        assert!(running < 1_000_000, "the steps were done before the cancel");
        let start = Instant::now();
        let (status, body) = request(address, "POST", cancel, b"");
        assert_eq!(status, 200, "{cancel}: {body}");
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "{cancel} took {:?}",
            start.elapsed()
        );
        let after = timed_step(address).0;
        std::thread::sleep(Duration::from_millis(500));
        assert_eq!(timed_step(address).0, after, "{cancel}: steps went on");
    }
}

#[test]
fn a_cross_origin_post_or_a_foreign_host_is_refused_and_the_page_s_own_are_obeyed() {
    let address = serve(small(13), false, Speed::Real);
    for (head, what) in [
        (
            format!("Host: {address}\r\nOrigin: http://evil.example"),
            "cross-origin",
        ),
        ("Host: evil.example".to_string(), "foreign Host"),
        (
            "Host: evil.example\r\nOrigin: http://evil.example".to_string(),
            "rebinding",
        ),
        (format!("Host: {address}\r\nOrigin: null"), "opaque origin"),
    ] {
        for path in ["/control?action=pause", "/settings?seed=99"] {
            let (status, reply) = post(address, path, &head);
            assert_eq!(status, 403, "{what} {path}: {reply}");
        }
    }
    let reply = raw(
        address,
        b"GET /state.json HTTP/1.1\r\nHost: evil.example:80\r\n\r\n",
    );
    assert_eq!(status_of(&reply), 403, "{reply}");
    let reply = raw(
        address,
        format!("GET /stream HTTP/1.1\r\nHost: {address}\r\nOrigin: http://evil.example\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n").as_bytes(),
    );
    assert_eq!(status_of(&reply), 403, "{reply}");
    let s = state(address);
    assert_eq!(s["frame"]["paused"], false, "a refused request paused it");
    assert_eq!(s["hello"]["generation"], 0, "a refused request reset it");
    // the page's own origin, by address or as localhost, and no origin (curl)
    let port = address.port();
    for head in [
        format!("Host: {address}\r\nOrigin: http://{address}"),
        format!("Host: localhost:{port}\r\nOrigin: http://localhost:{port}"),
        format!("Host: {address}"),
    ] {
        let (status, reply) = post(address, "/control?action=pause", &head);
        assert_eq!(status, 200, "{head}: {reply}");
    }
    assert_eq!(state(address)["frame"]["paused"], true);
}

#[test]
fn hundreds_of_slow_drip_connections_leave_the_page_loadable() {
    let address = serve(small(14), false, Speed::Real);
    let mut drips: Vec<TcpStream> = (0..520)
        .filter_map(|_| TcpStream::connect(address).ok())
        .collect();
    let started = Instant::now();
    let deadline = started + Duration::from_secs(25);
    let mut loaded = false;
    while Instant::now() < deadline && !loaded {
        for d in &mut drips {
            let _ = d.write_all(b"G");
        }
        std::thread::sleep(Duration::from_millis(1500));
        let reply = raw(
            address,
            format!("GET / HTTP/1.1\r\nHost: {address}\r\n\r\n").as_bytes(),
        );
        loaded = status_of(&reply) == 200 && reply.contains("<canvas");
    }
    assert!(loaded, "the page did not load within 25 s");
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "the page loaded only after {:?}",
        started.elapsed()
    );
}

#[test]
fn a_request_still_unfinished_at_its_deadline_is_closed() {
    let address = serve(small(15), true, Speed::Real);
    let mut drip = TcpStream::connect(address).unwrap();
    drip.set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let start = Instant::now();
    let mut reply = Vec::new();
    let closed = loop {
        if drip.write_all(b"G").is_err() {
            break true;
        }
        let mut buf = [0u8; 512];
        match std::io::Read::read(&mut drip, &mut buf) {
            Ok(0) => break true,
            Ok(n) => reply.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(_) => break true,
        }
        if start.elapsed() > Duration::from_secs(30) {
            break false;
        }
        std::thread::sleep(Duration::from_millis(900));
    };
    assert!(closed, "a connection sending a byte a second was held 30 s");
    let reply = String::from_utf8_lossy(&reply);
    assert!(reply.is_empty() || status_of(&reply) == 408, "{reply}");
    assert!(
        start.elapsed() >= Duration::from_secs(5),
        "closed after {:?}",
        start.elapsed()
    );
}

#[test]
fn head_answers_carry_the_length_but_no_body() {
    let address = serve(small(16), true, Speed::Real);
    for path in ["/", "/state.json", "/field.png"] {
        let reply = raw(
            address,
            format!("HEAD {path} HTTP/1.1\r\nHost: {address}\r\n\r\n").as_bytes(),
        );
        assert_eq!(status_of(&reply), 200, "{path}: {reply:.200}");
        let (head, body) = reply.split_once("\r\n\r\n").unwrap();
        assert!(
            body.is_empty(),
            "{path}: a HEAD answer has a body of {}",
            body.len()
        );
        let length: usize = head
            .lines()
            .find_map(|l| l.strip_prefix("Content-Length: "))
            .unwrap()
            .parse()
            .unwrap();
        assert!(length > 0, "{path}: {head}");
    }
}

#[test]
fn a_websocket_upgrade_without_its_key_or_version_is_refused() {
    let address = serve(small(17), true, Speed::Real);
    for missing in [
        "Sec-WebSocket-Version: 13\r\n",
        "Sec-WebSocket-Key: short\r\nSec-WebSocket-Version: 13\r\n",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 8\r\n",
    ] {
        let reply = raw(
            address,
            format!("GET /stream HTTP/1.1\r\nHost: {address}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n{missing}\r\n").as_bytes(),
        );
        assert!(
            matches!(status_of(&reply), 400 | 426),
            "{missing}: {reply:.300}"
        );
    }
}

#[test]
fn conflicting_content_lengths_or_a_transfer_encoding_are_refused() {
    let address = serve(small(18), true, Speed::Real);
    for head in [
        "Content-Length: 0\r\nContent-Length: 40",
        "Content-Length: 40\r\nContent-Length: 0",
        "Transfer-Encoding: chunked",
        "Content-Length: 0\r\nTransfer-Encoding: chunked",
    ] {
        let (status, reply) = post(
            address,
            "/control?action=play",
            &format!("Host: {address}\r\n{head}"),
        );
        assert_eq!(status, 400, "{head}: {reply}");
    }
    assert_eq!(state(address)["frame"]["paused"], true);
}

#[test]
fn bad_speed_or_paused_values_in_the_settings_are_refused_naming_the_key() {
    let address = serve(small(19), true, Speed::Real);
    for (path, says) in [
        ("/settings?speed=NaN", "speed=NaN"),
        ("/settings?paused=maybe", "paused=maybe"),
        ("/control?action=play&stpes=3", "stpes"),
    ] {
        let (status, body) = request(address, "POST", path, b"");
        assert_eq!(status, 400, "{path}: {body}");
        assert!(body.contains(says), "{path}: {body}");
    }
    let s = state(address);
    assert_eq!(
        (
            s["frame"]["paused"].clone(),
            s["hello"]["generation"].clone()
        ),
        (true.into(), 0.into())
    );
    let (status, body) = request(address, "POST", "/settings?speed=10x&paused=false", b"");
    assert_eq!(status, 200, "{body}");
    let s = state(address);
    assert_eq!(
        (s["frame"]["speed"].clone(), s["frame"]["paused"].clone()),
        ("10x".into(), false.into())
    );
}

#[test]
fn a_policy_trained_for_other_sensors_is_named_in_a_warning() {
    let address = serve(small(20), true, Speed::Real);
    let (status, body) = request(
        address,
        "POST",
        "/settings?controller=policy:robot-annulus-8bit.policy&sensors=disc",
        b"",
    );
    assert_eq!(status, 200, "{body}");
    let warning = state(address)["hello"]["warning"].to_string();
    assert!(
        warning.contains("sensor model robot (this run: disc)"),
        "{warning}"
    );
    let (status, body) = request(address, "POST", "/settings?controller=oc", b"");
    assert_eq!(status, 200, "{body}");
    assert!(state(address)["hello"]["warning"].is_null());
}
