//! A view of a world someone else steps (`View::follow`, what the Python
//! environments' `render_mode="human"` serves): viewers see each state it
//! is given, the page's controls are refused, and dropping the follower
//! stops the server.

mod common;

use common::{request, small, state};
use std::net::TcpStream;
use std::time::Duration;
use tungstenite::Message;
use view::session::Frame;
use view::View;

fn next_json(socket: &mut tungstenite::WebSocket<TcpStream>) -> Option<serde_json::Value> {
    loop {
        match socket.read() {
            Ok(Message::Text(t)) => return Some(serde_json::from_str(&t).unwrap()),
            Ok(Message::Close(_)) | Err(_) => return None,
            Ok(_) => {}
        }
    }
}

#[test]
fn viewers_see_every_state_the_owner_publishes_last_and_dropping_it_stops_the_server() {
    let (mut sim, mut controller) = small(4).choices(None).scenario().unwrap().build().unwrap();
    let follower = View::follow("127.0.0.1:0".parse().unwrap(), &sim).unwrap();
    let address = follower.address();
    assert_eq!(follower.url(), format!("http://{address}/"));
    let stream = TcpStream::connect(address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let mut socket = tungstenite::client(format!("ws://{address}/stream").as_str(), stream)
        .unwrap()
        .0;
    let hello = next_json(&mut socket).unwrap();
    assert_eq!(
        (hello["t"].as_str(), hello["generation"].as_u64()),
        (Some("hello"), Some(0))
    );
    assert_eq!(next_json(&mut socket).unwrap()["step"], 0);

    // the owner steps far faster than frames are sent: the last one arrives
    for _ in 0..300 {
        sim.step(controller.as_mut());
        follower.step(&sim);
    }
    let mut frames = 0;
    loop {
        let frame = next_json(&mut socket).unwrap();
        frames += 1;
        if frame["step"] == 300 {
            break;
        }
    }
    assert!(frames < 300, "{frames} frames for 300 steps: not limited");
    let served = state(address)["frame"].clone();
    // as the server writes it
    let own: serde_json::Value =
        serde_json::from_str(&serde_json::to_string(&Frame::of(&sim)).unwrap()).unwrap();
    assert_eq!(served["robots"], own["robots"]);
    assert_eq!(served["pucks"], own["pucks"]);
    assert_eq!(served["eval"], own["eval"]);

    for path in [
        "/control?action=play",
        "/settings?robots=3",
        "/policy?name=a.policy",
    ] {
        let (status, body) = request(address, "POST", path, b"");
        assert_eq!(status, 400, "{path}: {body}");
        assert!(
            body.contains("follows a world its owner steps"),
            "{path}: {body}"
        );
    }
    assert_eq!(state(address)["frame"]["step"], 300);

    sim.reset_episode();
    follower.reset(&sim).unwrap();
    let hello = next_json(&mut socket).unwrap();
    assert_eq!(
        (hello["t"].as_str(), hello["generation"].as_u64()),
        (Some("hello"), Some(1))
    );
    assert_eq!(state(address)["frame"]["episode_step"], 0);

    drop(follower);
    assert!(
        TcpStream::connect(address).is_err(),
        "still listening on {address}"
    );
    // the viewer's stream ends
    while next_json(&mut socket).is_some() {}
}
