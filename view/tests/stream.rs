//! The view's server without a browser: viewers get a hello and frames
//! over a WebSocket, controls and settings, a viewer that stops reading is
//! dropped, and hundreds of idle or half-open connections do not stop it.

mod common;

use common::{request, serve, small, state, wait_for_step};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};
use tungstenite::Message;
use view::Speed;

fn viewer(address: std::net::SocketAddr) -> tungstenite::WebSocket<TcpStream> {
    let stream = TcpStream::connect(address).unwrap();
    tungstenite::client(format!("ws://{address}/stream").as_str(), stream)
        .unwrap()
        .0
}

fn next_json(socket: &mut tungstenite::WebSocket<TcpStream>) -> serde_json::Value {
    loop {
        if let Message::Text(t) = socket.read().unwrap() {
            return serde_json::from_str(&t).unwrap();
        }
    }
}

#[test]
fn a_viewer_gets_the_hello_then_frames_whose_step_advances() {
    let address = serve(small(1), false, Speed::Ten);
    let mut socket = viewer(address);
    let hello = next_json(&mut socket);
    assert_eq!(hello["t"], "hello");
    assert_eq!(hello["arena"][0], 800.0);
    let first = next_json(&mut socket);
    let mut later = first.clone();
    for _ in 0..10 {
        later = next_json(&mut socket);
    }
    assert_eq!(later["t"], "frame");
    assert!(
        later["step"].as_u64() > first["step"].as_u64(),
        "{first} {later}"
    );
    assert_eq!(later["robots"].as_array().unwrap().len(), 20);
    assert_eq!(later["in_band"].as_array().unwrap().len(), 40);
}

#[test]
fn controls_step_exactly_and_refused_settings_change_nothing() {
    let address = serve(small(2), true, Speed::Real);
    let (status, _) = request(address, "POST", "/control?action=step&steps=250", b"");
    assert_eq!(status, 200);
    let at = wait_for_step(address, 250);
    for (path, says) in [
        ("/settings?robots=0", "robots = 0: outside"),
        ("/settings?noise=-1", "noise"),
        ("/settings?field=/etc/passwd", "field=/etc/passwd"),
        ("/settings?controller=policy:none.policy", "none.policy"),
        ("/control?action=jump", "action=jump"),
        ("/control?speed=warp", "speed=warp"),
    ] {
        let (status, body) = request(address, "POST", path, b"");
        assert_eq!(status, 400, "{path}: {body}");
        assert!(body.contains(says), "{path}: {body}");
    }
    let (status, body) = request(address, "POST", "/policy?name=x.policy", &[0u8; 600]);
    assert_eq!(status, 400, "{body}");
    assert!(body.contains("x.policy"), "{body}");
    let mut big = TcpStream::connect(address).unwrap();
    big.write_all(b"POST /policy?name=y.policy HTTP/1.1\r\nContent-Length: 100000000\r\n\r\n")
        .unwrap();
    let mut reply = String::new();
    big.read_to_string(&mut reply).unwrap();
    assert!(reply.starts_with("HTTP/1.1 413"), "{reply}");
    assert_eq!(
        state(address),
        at,
        "a refused request changed the simulation"
    );
    assert_eq!(request(address, "GET", "/../Cargo.toml", b"").0, 404);
    assert_eq!(request(address, "PUT", "/", b"").0, 405);
}

#[test]
fn a_shipped_policy_file_drives_the_robots_after_a_settings_change() {
    let address = serve(small(3), true, Speed::Real);
    let (status, body) = request(
        address,
        "POST",
        "/settings?controller=policy:oc-heuristic.policy",
        b"",
    );
    assert_eq!(status, 200, "{body}");
    let s = state(address);
    assert_eq!(s["hello"]["generation"], 1);
    assert!(s["hello"]["settings"]
        .to_string()
        .contains("policy:oc-heuristic.policy"));
}

#[test]
fn a_viewer_that_stops_reading_is_dropped_and_the_others_go_on() {
    let mut settings = small(4);
    settings.world.pucks = Some(600);
    let address = serve(settings, false, Speed::Max);
    let idle = viewer(address);
    let mut reader = viewer(address);
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let frame = next_json(&mut reader);
        if frame["t"] == "frame" && frame["viewers"] == 1 {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the idle viewer was never dropped"
        );
    }
    drop(idle);
}

#[test]
fn the_server_survives_hundreds_of_idle_and_half_open_connections() {
    let address = serve(small(5), false, Speed::Real);
    let idle: Vec<TcpStream> = (0..200)
        .map(|_| TcpStream::connect(address).unwrap())
        .collect();
    let mut viewers: Vec<_> = (0..20).map(|_| viewer(address)).collect();
    // half a request, never finished
    let mut half = TcpStream::connect(address).unwrap();
    half.write_all(b"GET /state.json HTTP/1.1\r\nHost: x\r\n")
        .unwrap();
    let s = state(address);
    assert!(s["frame"]["step"].as_u64().is_some());
    for v in &mut viewers {
        assert_eq!(next_json(v)["t"], "hello");
    }
    drop(idle);
    drop(half);
}
