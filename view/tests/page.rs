//! The live view's page in headless Chromium: it draws the world, its
//! controls pause, step and reset the simulation, URL parameters set it,
//! and refused settings leave it as it was with a message on the page.

mod browser;
mod common;

use browser::Browser;
use common::{request, serve, small, state, wait_for_step};
use view::Speed;

const SIZE: (u32, u32) = (1100, 820);

/// Pixels of the world's canvas whose colour is near `rgb`.
fn pixels_like(browser: &mut Browser, rgb: [u8; 3]) -> u64 {
    let [r, g, b] = rgb;
    browser
        .eval(&format!(
            "(() => {{ const c = document.getElementById('world'); const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - {r}) < 8 && Math.abs(d[i + 1] - {g}) < 8 && Math.abs(d[i + 2] - {b}) < 8) n++; return n; }})()"
        ))
        .as_u64()
        .unwrap()
}

#[test]
fn the_page_loads_and_draws_non_blank_frames_of_robots_and_pucks() {
    let address = serve(small(1), false, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("Number(document.documentElement.dataset.painted) > 10", 60);
    let robots = pixels_like(&mut page, [0, 100, 200]);
    let pucks = pixels_like(&mut page, [200, 44, 44]) + pixels_like(&mut page, [40, 180, 80]);
    assert!(robots > 50, "{robots} robot pixels");
    assert!(pucks > 100, "{pucks} puck pixels");
    let painted: u64 = page.data("step").parse().unwrap();
    assert!(painted > 0);
    // shown undistorted: its box on the page has the arena's shape
    let shape = page.eval("(() => { const c = document.getElementById('world'); const r = c.getBoundingClientRect(); return [r.width / r.height, c.width / c.height]; })()");
    let (shown, drawn) = (shape[0].as_f64().unwrap(), shape[1].as_f64().unwrap());
    assert!(
        (shown - drawn).abs() < 0.01 && (drawn - 1.0).abs() < 0.01,
        "{shape}"
    );
}

#[test]
fn pause_stops_the_step_counter_and_a_single_step_advances_it_by_exactly_one() {
    let address = serve(small(2), false, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("Number(document.documentElement.dataset.step) > 5", 60);
    page.eval("window.dispatchEvent(new KeyboardEvent('keydown', { key: ' ' }))");
    page.wait_for("document.documentElement.dataset.paused === 'true'", 30);
    std::thread::sleep(std::time::Duration::from_millis(300));
    let paused: u64 = page.data("step").parse().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(600));
    assert_eq!(
        page.data("step").parse::<u64>().unwrap(),
        paused,
        "the step moved while paused"
    );
    assert_eq!(
        state(address)["frame"]["step"],
        paused,
        "the page shows the server's step"
    );
    page.eval("window.dispatchEvent(new KeyboardEvent('keydown', { key: 's' }))");
    page.wait_for(
        &format!(
            "Number(document.documentElement.dataset.step) === {}",
            paused + 1
        ),
        30,
    );
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(page.data("step").parse::<u64>().unwrap(), paused + 1);
}

#[test]
fn reset_with_a_seed_reproduces_the_same_frames() {
    let address = serve(small(3), true, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
    let mut picture = |seed: u64| {
        let before = page
            .eval("document.documentElement.dataset.generation")
            .as_str()
            .unwrap()
            .to_string();
        page.eval(&format!("document.getElementById('resetSeed').value = '{seed}'; document.getElementById('reset').click()"));
        // the reset's new generation, not the step 0 the page may show already
        // (a step request overtaking the page's reset would be undone by it)
        page.wait_for(
            &format!("document.documentElement.dataset.generation !== '{before}' && document.documentElement.dataset.step === '0'"),
            30,
        );
        let (status, body) = request(address, "POST", "/control?action=step&steps=40", b"");
        assert_eq!(status, 200, "{body}");
        wait_for_step(address, 40);
        page.wait_for("document.documentElement.dataset.step === '40' && document.documentElement.dataset.field === document.documentElement.dataset.generation", 30);
        // painted after the field image came
        std::thread::sleep(std::time::Duration::from_millis(200));
        page.eval("document.getElementById('world').toDataURL()")
            .as_str()
            .unwrap()
            .to_string()
    };
    let first = picture(9);
    let other = picture(10);
    let again = picture(9);
    assert!(
        first == again,
        "seed 9 drew another picture the second time"
    );
    assert!(first != other, "seeds 9 and 10 drew the same picture");
}

#[test]
fn the_sensors_and_the_camera_view_are_drawn_on_request_and_kept_in_the_address() {
    let mut settings = view::ViewSettings::default();
    settings.world.sensors = sim::scenario::sensor_choice::SensorChoice::Robot(None);
    let address = serve(settings, true, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
    assert_eq!(page.data("footprints"), "0");
    let yellow = pixels_like(&mut page, [255, 255, 0]);
    // on: per robot (tv75's 5) three photo-transistors and the camera's floor
    page.eval("document.dispatchEvent(new KeyboardEvent('keydown', { key: 'f', bubbles: true }))");
    page.wait_for("document.documentElement.dataset.footprints === '20'", 30);
    assert!(pixels_like(&mut page, [255, 255, 0]) > yellow + 15);
    assert!(page
        .eval("location.search")
        .as_str()
        .unwrap()
        .contains("footprints=true"));
    // a page opened at that address draws them from the start
    let search = page.eval("location.search").as_str().unwrap().to_string();
    let mut shared = Browser::open(&format!("http://{address}/{search}"), SIZE);
    shared.wait_for("document.documentElement.dataset.footprints === '20'", 60);
    page.eval("document.getElementById('footprints').click()");
    page.wait_for("document.documentElement.dataset.footprints === '0'", 30);
}

#[test]
fn url_parameters_set_the_simulation_and_the_address_bar_keeps_them() {
    let address = serve(small(1), true, Speed::Real);
    let mut page = Browser::open(
        &format!("http://{address}/?robots=3&pucks=12&seed=77&field=letter:T"),
        SIZE,
    );
    page.wait_for("document.documentElement.dataset.generation === '1'", 60);
    let s = state(address);
    assert_eq!(s["frame"]["robots"].as_array().unwrap().len(), 12);
    assert_eq!(s["frame"]["pucks"].as_array().unwrap().len(), 24);
    let search = page.eval("location.search").as_str().unwrap().to_string();
    assert!(
        search.contains("seed=77") && search.contains("robots=3") && search.contains("letter%3AT"),
        "{search}"
    );
}

#[test]
fn a_world_setting_the_page_has_no_control_of_its_own_for_gets_a_field_that_sets_it() {
    let address = serve(small(2), true, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
    // the stuck limit: a world setting the page's markup does not name
    page.eval("const f = document.getElementById('settings'); f.elements.stuck_limit.value = '700'; f.requestSubmit()");
    page.wait_for(
        "new URLSearchParams(location.search).get('stuck_limit') === '700'",
        30,
    );
    let settings = state(address)["hello"]["settings"].clone();
    assert!(
        settings
            .as_array()
            .unwrap()
            .iter()
            .any(|pair| pair == &serde_json::json!(["stuck_limit", "700"])),
        "{settings}"
    );
}

#[test]
fn a_bad_setting_or_policy_file_is_refused_with_a_message_and_nothing_else_changes() {
    let address = serve(small(4), true, Speed::Real);
    let mut page = Browser::open(&format!("http://{address}/"), SIZE);
    page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
    let before = state(address);
    page.eval("const f = document.getElementById('settings'); f.elements.robots.value = '0'; f.elements.seed.value = '5'; f.requestSubmit()");
    page.wait_for("document.documentElement.dataset.error !== ''", 30);
    let error = page.data("error");
    assert!(
        error.contains("robots = 0") && error.contains("outside"),
        "{error}"
    );
    page.eval("const d = new DataTransfer(); d.items.add(new File([new Uint8Array([1, 2, 3, 4])], 'broken.policy')); const u = document.getElementById('upload'); u.files = d.files; u.dispatchEvent(new Event('change'))");
    page.wait_for(
        "document.documentElement.dataset.error.includes('broken.policy')",
        30,
    );
    let after = state(address);
    assert_eq!(after["hello"], before["hello"], "the settings changed");
    assert_eq!(after["frame"]["step"], before["frame"]["step"]);
    assert_eq!(after["frame"]["robots"], before["frame"]["robots"]);
}

#[test]
fn a_learning_world_shows_its_progress_and_its_companion_beside_it() {
    let (mut sim, mut controller) = small(5).choices(None).scenario().unwrap().build().unwrap();
    let companion_address = serve(small(6), false, Speed::Real);
    let companion = view::Companion {
        label: "The exported policy acting".into(),
        url: format!("http://{companion_address}/"),
    };
    let follower =
        view::View::follow_beside("127.0.0.1:0".parse().unwrap(), &sim, Some(companion)).unwrap();
    let mut page = Browser::open(&follower.url(), (1600, 820));
    for _ in 0..40 {
        sim.step(controller.as_mut());
    }
    follower.step_learning(
        &sim,
        view::Learning {
            states_visited: 17,
            states_total: 256,
            exploration: 0.05,
            greedy_step: Some(20),
        },
    );
    page.wait_for("document.documentElement.dataset.step === '40'", 60);
    let stats = page.eval("document.getElementById('stats').textContent");
    let stats = stats.as_str().unwrap();
    for shown in [
        "states visited17 of 256",
        "exploration0.050",
        "greedy table of step20",
    ] {
        assert!(stats.contains(shown), "{shown:?} not in {stats:?}");
    }
    // a followed world takes no controls: the page shows none
    assert_eq!(
        page.eval("[document.getElementById('play').offsetParent, document.getElementById('settings').offsetParent]"),
        serde_json::json!([null, null])
    );
    assert_eq!(
        page.eval("document.getElementById('beside').hidden"),
        serde_json::json!(false)
    );
    assert_eq!(
        page.eval("document.getElementById('besideLabel').textContent"),
        serde_json::json!("The exported policy acting")
    );
    // the companion's own page (another origin) runs inside the frame,
    // beside the world: its server counts it as a viewer
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while state(companion_address)["frame"]["viewers"] != 1 {
        assert!(
            std::time::Instant::now() < deadline,
            "the frame never connected"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let boxes = page.eval("(() => { const w = document.getElementById('world').getBoundingClientRect(); const f = document.getElementById('companion').getBoundingClientRect(); return [w.right, f.left, f.width]; })()");
    assert!(
        boxes[1].as_f64() > boxes[0].as_f64() && boxes[2].as_f64().unwrap() > 400.0,
        "{boxes}"
    );
}

#[test]
fn a_policy_trained_for_other_sensors_chosen_on_the_page_shows_the_warning() {
    let address = serve(small(7), true, Speed::Real);
    // the page's own POST (its Origin is the server's): obeyed
    let mut page = Browser::open(
        &format!("http://{address}/?controller=policy:robot-annulus-8bit.policy&sensors=disc"),
        SIZE,
    );
    page.wait_for("document.documentElement.dataset.generation === '1'", 60);
    page.wait_for("document.documentElement.dataset.warning !== ''", 30);
    let warning = page.data("warning");
    assert!(
        warning.contains("sensor model robot (this run: disc)"),
        "{warning}"
    );
    assert_eq!(
        page.eval("document.getElementById('warning').textContent")
            .as_str()
            .unwrap(),
        warning
    );
}

#[test]
fn another_site_s_page_in_the_browser_cannot_drive_the_view() {
    let target = serve(small(8), false, Speed::Real);
    // another origin (another port): what any page open in the browser is
    let other = serve(small(9), true, Speed::Real);
    let mut page = Browser::open(&format!("http://{other}/"), SIZE);
    page.wait_for("document.documentElement.dataset.ready === 'true'", 60);
    let sent = page.eval(&format!(
        "fetch('http://{target}/control?action=pause', {{ method: 'POST', mode: 'no-cors' }}).then(() => 'sent', (e) => 'failed: ' + e)"
    ));
    assert_eq!(sent, "sent", "the browser did not send the request");
    let socket = page.eval(&format!(
        "new Promise((done) => {{ const w = new WebSocket('ws://{target}/stream'); w.onopen = () => done('open'); w.onerror = () => done('refused'); }})"
    ));
    assert_eq!(socket, "refused");
    let s = state(target);
    assert_eq!(s["frame"]["paused"], false, "another site's page paused it");
}
