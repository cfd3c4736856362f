//! The firmware's USB serial port in simavr, against the host written in
//! `tests::zumo` (`usb_host`): enumeration and descriptors, the CDC-ACM
//! requests, log frames over the bulk IN endpoint, the 1200-baud touch,
//! a host that stops reading, the cable pulled and plugged back.

use firmware::embedded;
use firmware::usb::{BOOT_KEY, PID, VID};
use shared::{LogFrame, PolicyBlob, RunMode};
use tests::usb_host::setup;
use tests::zumo::Zumo;

/// The bulk IN endpoint (`firmware::usb::IN_EP`; the configuration descriptor says so).
const BULK_IN: u8 = 3;

/// Splits a byte stream at the frames' delimiter (whole frames only).
fn frames_of(bytes: &[u8]) -> Vec<&[u8]> {
    let mut out: Vec<&[u8]> = bytes.split(|b| *b == LogFrame::DELIMITER).collect();
    out.pop(); // after the last delimiter: not a whole frame
    out
}

fn plugged_zumo() -> Zumo {
    let mut z = Zumo::boot();
    z.plug_usb(true);
    z.run_ms(100);
    z
}

/// A host that has enumerated the robot and opened its port.
fn open_port() -> Zumo {
    let mut z = Zumo::boot();
    z.usb_open(5);
    z
}

#[test]
fn the_robot_enumerates_as_a_cdc_acm_serial_port_named_by_its_robot_id() {
    let mut z = plugged_zumo();
    assert!(!z.usb_detached(), "VBUS seen: the device attaches");
    let (device, config) = z.usb_enumerate(5);
    assert_eq!(z.usb_address(), Some(5), "SET_ADDRESS took effect");

    // Device descriptor: USB 2.0, IAD class triple, EP0 64 bytes, VID/PID.
    assert_eq!(device.len(), 18);
    assert_eq!(&device[..2], &[18, 1]);
    assert_eq!(
        (device[4], device[5], device[6], device[7]),
        (0xEF, 0x02, 0x01, 64)
    );
    assert_eq!(u16::from_le_bytes([device[8], device[9]]), VID);
    assert_eq!(u16::from_le_bytes([device[10], device[11]]), PID);

    // Configuration: two interfaces; CDC communication (02/02) with an
    // interrupt IN endpoint, CDC data (0A) with bulk OUT and bulk IN 64.
    assert_eq!(config[1], 2);
    assert_eq!(
        usize::from(u16::from_le_bytes([config[2], config[3]])),
        config.len()
    );
    assert_eq!(config[4], 2, "interfaces");
    let mut interfaces = Vec::new();
    let mut endpoints = Vec::new();
    let mut i = 0;
    while i < config.len() {
        let d = &config[i..i + usize::from(config[i])];
        match d[1] {
            4 => interfaces.push((d[5], d[6])),
            5 => endpoints.push((d[2], d[3], u16::from_le_bytes([d[4], d[5]]))),
            _ => {}
        }
        i += usize::from(config[i]);
    }
    assert_eq!(interfaces, [(0x02, 0x02), (0x0A, 0x00)]);
    assert_eq!(endpoints, [(0x81, 3, 8), (0x02, 2, 64), (0x83, 2, 64)]);

    assert_eq!(z.usb_string(device[16]), embedded::USB_SERIAL);
    assert_eq!(embedded::USB_SERIAL, "robot-000");
    assert_eq!(z.usb_string(device[15]), firmware::usb::PRODUCT);
    let configuration = z.usb_control(setup(0x80, 8, 0, 0, 1), &[]).unwrap();
    assert_eq!(configuration, [1]);
}

/// A host resets the bus whenever it likes; the firmware spends most of a
/// 20 ms period deciding and logging, so the reset lands at every point of
/// its loop in turn (offsets 0 to 19 ms after a period starts, 1 ms apart).
#[test]
fn the_robot_enumerates_wherever_in_its_period_the_host_resets_the_bus() {
    for offset_ms in 0..20 {
        let mut z = plugged_zumo();
        let periods = z.period_cycles().len();
        while z.period_cycles().len() == periods {
            z.run_us(100);
        }
        z.run_ms(offset_ms);
        let (device, _) = z.usb_enumerate(9);
        assert_eq!(
            device.len(),
            18,
            "device descriptor after a reset {offset_ms} ms into a period"
        );
        assert_eq!(
            z.usb_address(),
            Some(9),
            "address after a reset {offset_ms} ms into a period"
        );
    }
}

#[test]
fn line_coding_and_control_line_state_are_answered() {
    let mut z = plugged_zumo();
    z.usb_enumerate(7);
    z.usb_set_line_coding(57_600).unwrap();
    assert_eq!(z.usb_line_coding(), (57_600, 0, 0, 8));
    z.usb_set_dtr(true).unwrap();
    z.usb_set_dtr(false).unwrap();
    // An unknown class request is refused, and the port still answers.
    assert!(z.usb_control(setup(0xA1, 0x7F, 0, 0, 4), &[]).is_err());
    assert_eq!(z.usb_line_coding().0, 57_600);
}

#[test]
fn log_frames_on_usb_are_the_frames_on_txd1() {
    let mut z = open_port();
    let uart_before = z.uart_bytes().len();
    let usb = z.usb_read_bulk(BULK_IN, 300_000);
    let uart = z.uart_bytes()[uart_before..].to_vec();
    let usb_frames = frames_of(&usb);
    assert!(
        usb_frames.len() >= 12,
        "{} frames over USB in 300 ms",
        usb_frames.len()
    );
    // Every whole frame read over USB is byte for byte one of TXD1's, in order.
    let uart_frames = frames_of(&uart);
    let first = uart_frames
        .iter()
        .position(|f| *f == usb_frames[1])
        .expect("a USB frame that TXD1 never sent");
    for (k, f) in usb_frames[1..].iter().enumerate() {
        assert_eq!(Some(f), uart_frames.get(first + k), "frame {k} differs");
        let frame = LogFrame::decode(f).expect("a USB frame that does not decode");
        assert_eq!(frame.mode, RunMode::Idle);
    }
    // `host replay` reads the USB capture as it reads TXD1's over the same frames.
    let capture = |frames: &[&[u8]]| {
        let mut bytes = Vec::new();
        for f in frames {
            bytes.extend_from_slice(f);
            bytes.push(LogFrame::DELIMITER);
        }
        bytes
    };
    let n = usb_frames.len() - 1;
    let policy = PolicyBlob::decode(embedded::POLICY_BLOB).unwrap();
    let report = |bytes: &[u8]| {
        let recording = host::robot::log_file::parse(bytes).unwrap();
        host::robot::replay::replay(&recording, &policy, None, Default::default())
    };
    let over_usb = report(&capture(&usb_frames[1..]));
    let over_txd1 = report(&capture(&uart_frames[first..first + n]));
    assert_eq!((over_usb.frames, over_usb.diverged), (n as u64, 0));
    assert_eq!(over_usb.to_string(), over_txd1.to_string());
}

#[test]
fn a_host_that_stops_reading_never_blocks_the_control_period() {
    let mut z = open_port();
    z.run_ms(20);
    let before = z.period_cycles().len();
    // The host holds the port open but reads nothing for half a second.
    z.run_ms(500);
    let periods = &z.period_cycles()[before..];
    let period = 20_000 / 4 * 64;
    assert!(periods.len() >= 24);
    assert!(
        periods.iter().all(|p| p.abs_diff(period) < 64),
        "periods {periods:?}"
    );
    // TXD1 lost nothing meanwhile; USB dropped whole frames and then
    // delivers whole frames again.
    let ticks: Vec<u32> = z.frames().into_iter().map(|f| f.unwrap().tick).collect();
    assert!(ticks.windows(2).all(|w| w[1] == w[0] + 1));
    let usb = z.usb_read_bulk(BULK_IN, 100_000);
    let frames = frames_of(&usb);
    assert!(frames.len() >= 3);
    for f in &frames[1..] {
        LogFrame::decode(f).expect("a frame cut by the drop");
    }
}

#[test]
fn a_1200_baud_touch_stops_the_motors_stores_the_key_and_resets_by_the_watchdog() {
    let mut z = open_port();
    z.run_ms(40);
    assert!(z.watchdog_resets().is_empty());
    z.usb_set_line_coding(1200).unwrap();
    z.usb_set_dtr(false).unwrap();
    z.run_ms(2);
    assert_eq!(z.duties(), (0, 0));
    assert_eq!(z.boot_key(), BOOT_KEY);
    // The watchdog (125 ms) resets the chip with the key in place: the
    // bootloader would stay in itself.
    let ms = z
        .run_until_watchdog_reset(400)
        .expect("no watchdog reset within 400 ms of the touch");
    println!("watchdog reset {ms} ms after the touch");
    assert!(
        (120..=140).contains(&ms),
        "{ms} ms, not the 125 ms watchdog"
    );
    assert_eq!(z.watchdog_resets(), [BOOT_KEY]);
}

#[test]
fn a_touch_cancelled_by_dtr_in_time_does_not_reset() {
    let mut z = open_port();
    z.usb_set_line_coding(1200).unwrap();
    z.usb_set_dtr(false).unwrap();
    z.run_ms(50);
    assert_eq!(z.boot_key(), BOOT_KEY);
    z.usb_set_dtr(true).unwrap();
    z.run_ms(400);
    assert!(
        z.watchdog_resets().is_empty(),
        "reset after a cancelled touch"
    );
    assert_eq!(z.boot_key(), 0, "the key is cleared");
    let frames = z.frames();
    assert!(!frames.is_empty() && frames.iter().all(|f| f.is_ok()));
}

#[test]
fn pulling_the_cable_detaches_and_plugging_it_back_enumerates_again() {
    let mut z = open_port();
    z.plug_usb(false);
    z.run_ms(25);
    assert!(z.usb_detached());
    // On batteries the robot carries on: frames keep coming on TXD1.
    z.frames();
    z.run_ms(60);
    assert!(z.frames().len() >= 2);
    z.plug_usb(true);
    z.run_ms(25);
    assert!(!z.usb_detached());
    let (device, _) = z.usb_enumerate(9);
    assert_eq!(device.len(), 18);
    assert_eq!(z.usb_address(), Some(9));
    z.usb_set_dtr(true).unwrap();
    let usb = z.usb_read_bulk(BULK_IN, 100_000);
    assert!(frames_of(&usb).len() >= 3);
}

#[test]
fn a_suspended_bus_stops_nothing_and_wakes_up() {
    let mut z = open_port();
    z.suspend_usb(true);
    z.run_ms(60);
    assert!(z.frames().iter().all(|f| f.is_ok()));
    z.suspend_usb(false);
    z.run_ms(5);
    assert_eq!(z.usb_line_coding().0, 115_200);
}
