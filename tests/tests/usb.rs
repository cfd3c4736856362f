//! The firmware's USB serial port in simavr, against the host written in
//! `tests::zumo` (`usb_host`): enumeration and descriptors, the CDC-ACM
//! requests, log frames over the bulk IN endpoint, the 1200-baud touch,
//! a host that stops reading, the cable pulled and plugged back, suspend
//! and endpoint halts. The identities and descriptors the robot must
//! present are written here as literals from the specifications and
//! `../shared/docs/hardware.md`, never imported from the firmware.

use firmware::embedded;
use shared::{LogFrame, PolicyBlob, RunMode};
use tests::usb_host::{setup, split_descriptors, Stalled};
use tests::zumo::Zumo;

/// The bulk IN endpoint (the configuration descriptor says so).
const BULK_IN: u8 = 3;
/// The bulk OUT endpoint.
const BULK_OUT: u8 = 2;

// What the robot must present, written here from the specifications and
// the hardware facts, not taken from the firmware.

/// Pololu's vendor id (`../shared/docs/hardware.md` section 6).
const VID: u16 = 0x1FFB;
/// The A-Star 32U4 application's product id (the same section; the
/// bootloader's is 0x0101).
const PID: u16 = 0x2300;
/// The word at SRAM 0x0800 that sends the A-Star bootloader into itself
/// after a watchdog reset (the same section).
const BOOT_KEY: u16 = 0x7777;

/// The device descriptor (USB 2.0 table 9-8).
const DEVICE: [u8; 18] = [
    18, 1, // bLength, DEVICE
    0x00, 0x02, // bcdUSB 2.00
    0xEF, 0x02, 0x01, // class: miscellaneous, common class, interface association
    64,   // bMaxPacketSize0
    0xFB, 0x1F, // idVendor 0x1FFB
    0x00, 0x23, // idProduct 0x2300
    0x00, 0x01, // bcdDevice 1.00
    1, 2, 3, // iManufacturer, iProduct, iSerialNumber
    1, // bNumConfigurations
];

/// The configuration descriptor, descriptor by descriptor: USB 2.0 tables
/// 9-10, 9-12 and 9-13, the interface association descriptor of its ECN,
/// and the CDC-ACM functional descriptors of CDC 1.2 (header, union) and
/// its PSTN subclass document (call management, abstract control
/// management).
const CONFIGURATION: [&[u8]; 11] = [
    // 75 bytes, 2 interfaces, value 1, no string, bus powered without
    // remote wake-up, 100 mA (50 x 2 mA)
    &[9, 2, 75, 0, 2, 1, 0, 0x80, 50],
    // association: interfaces 0 and 1, CDC, ACM, no protocol, no string
    &[8, 0x0B, 0, 2, 0x02, 0x02, 0x00, 0],
    // interface 0, alternate 0, 1 endpoint, CDC communication, ACM, no protocol
    &[9, 4, 0, 0, 1, 0x02, 0x02, 0x00, 0],
    // CS_INTERFACE header: bcdCDC 1.10
    &[5, 0x24, 0x00, 0x10, 0x01],
    // call management: no capabilities, data interface 1
    &[5, 0x24, 0x01, 0x00, 1],
    // abstract control management: line coding and control line state
    &[4, 0x24, 0x02, 0x02],
    // union: interface 0 controls interface 1
    &[5, 0x24, 0x06, 0, 1],
    // endpoint 1 IN, interrupt, 8 bytes, every 255 ms
    &[7, 5, 0x81, 0x03, 8, 0, 255],
    // interface 1, alternate 0, 2 endpoints, CDC data
    &[9, 4, 1, 0, 2, 0x0A, 0x00, 0x00, 0],
    // endpoint 2 OUT, bulk, 64 bytes
    &[7, 5, 0x02, 0x02, 64, 0, 0],
    // endpoint 3 IN, bulk, 64 bytes
    &[7, 5, 0x83, 0x02, 64, 0, 0],
];

/// A string descriptor (USB 2.0 table 9-16) of ASCII text: UTF-16LE.
fn string_descriptor(text: &str) -> Vec<u8> {
    let mut d = vec![2 + 2 * text.len() as u8, 3];
    for c in text.bytes() {
        d.extend_from_slice(&[c, 0]);
    }
    d
}

/// The sensors' times while driving, in Timer3 ticks: between the white
/// (100 to 120) and black (400 to 420) of [`Zumo::calibrate`].
const SENSOR_TICKS: [Option<u16>; 3] = [Some(300), Some(200), Some(150)];

/// Splits a byte stream at the frames' delimiter (whole frames only).
fn frames_of(bytes: &[u8]) -> Vec<&[u8]> {
    let mut out: Vec<&[u8]> = bytes.split(|b| *b == LogFrame::DELIMITER).collect();
    out.pop(); // after the last delimiter: not a whole frame
    out
}

/// Reads the bulk IN endpoint for 100 ms: at least three frames, each
/// whole one after the first (which may have begun before the read)
/// decoding; `after` names what they follow.
fn frames_flow_again(z: &mut Zumo, after: &str) {
    let usb = z.usb_read_bulk(BULK_IN, 100_000);
    let frames = frames_of(&usb);
    assert!(
        frames.len() >= 3,
        "{} frames over USB after {after}",
        frames.len()
    );
    for f in &frames[1..] {
        LogFrame::decode(f).unwrap_or_else(|e| panic!("a frame cut by {after}: {e}"));
    }
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
fn a_malformed_descriptor_is_an_error_not_a_hang() {
    assert_eq!(
        split_descriptors(&[9, 2, 0, 0]),
        Err("descriptor at offset 0: bLength 9 with 4 bytes left".to_string())
    );
    assert_eq!(
        split_descriptors(&[2, 5, 0, 4]),
        Err("descriptor at offset 2: bLength 0 with 2 bytes left".to_string())
    );
    assert_eq!(
        split_descriptors(&[2, 5, 3, 4, 1]),
        Ok(vec![&[2u8, 5][..], &[3, 4, 1][..]])
    );
}

#[test]
fn the_robot_enumerates_as_a_cdc_acm_serial_port_named_by_its_robot_id() {
    let mut z = plugged_zumo();
    assert!(!z.usb_detached(), "VBUS seen: the device attaches");
    let e = z.usb_enumerate(5);
    assert_eq!(z.usb_address(), Some(5), "SET_ADDRESS took effect");

    assert_eq!(u16::from_le_bytes([e.device[8], e.device[9]]), VID);
    assert_eq!(u16::from_le_bytes([e.device[10], e.device[11]]), PID);
    assert_eq!(e.device, DEVICE);
    let sent = split_descriptors(&e.config).unwrap_or_else(|m| panic!("{m}: {:?}", e.config));
    assert_eq!(sent, CONFIGURATION);
    assert_eq!(e.config.len(), 75);

    assert_eq!(
        z.usb_string_descriptor(0),
        [4, 3, 0x09, 0x04],
        "English (US)"
    );
    assert_eq!(z.usb_string_descriptor(1), string_descriptor("zumo-swarm"));
    assert_eq!(
        z.usb_string_descriptor(2),
        string_descriptor("Zumo 32U4 robot")
    );
    assert_eq!(z.usb_string_descriptor(3), string_descriptor("robot-000"));
    assert_eq!(z.usb_string(3), embedded::USB_SERIAL);
    assert!(z
        .usb_control(setup(0x80, 6, 0x0304, 0x0409, 255), &[])
        .is_err());
    assert_eq!(z.usb_control(setup(0x80, 8, 0, 0, 1), &[]), Ok(vec![1]));
    assert_eq!(
        z.usb_control(setup(0x80, 0, 0, 0, 2), &[]),
        Ok(vec![0, 0]),
        "GET_STATUS: bus powered, no remote wake-up"
    );
}

/// A host resets the bus whenever it likes; the firmware spends most of a
/// 20 ms period deciding and logging, so the reset lands at every point of
/// its loop in turn (offsets 0 to 19 ms after a period starts, 1 ms apart).
#[test]
fn the_robot_enumerates_wherever_in_its_period_the_host_resets_the_bus() {
    let mut slowest_address = 0;
    for offset_ms in 0..20 {
        let mut z = plugged_zumo();
        let periods = z.period_cycles().len();
        while z.period_cycles().len() == periods {
            z.run_us(100);
        }
        z.run_ms(offset_ms);
        let e = z.usb_enumerate(9);
        assert_eq!(
            e.device, DEVICE,
            "device descriptor after a reset {offset_ms} ms into a period"
        );
        assert_eq!(
            z.usb_address(),
            Some(9),
            "address after a reset {offset_ms} ms into a period"
        );
        slowest_address = slowest_address.max(e.address_us);
    }
    println!("the address enabled at most {slowest_address} us after SET_ADDRESS's status stage");
    assert!(
        slowest_address <= 2_000,
        "the address took {slowest_address} us: USB 2.0 (9.2.6.3) allows 2 ms"
    );
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
    frames_flow_again(&mut z, "the drop");
}

/// A robot calibrated by the real procedure and driving (A pressed), its
/// port open on a host.
fn driving_zumo_on_usb() -> Zumo {
    let mut z = Zumo::boot();
    z.usb_open(5);
    z.calibrate();
    z.set_sensor_ticks(SENSOR_TICKS);
    z.press_a();
    z.run_ms(100);
    let frame = z
        .frames()
        .pop()
        .expect("no log frame")
        .expect("a frame that does not decode");
    assert_eq!(
        frame.mode,
        RunMode::Driving,
        "A pressed on a calibrated robot"
    );
    assert_ne!(z.duties(), (0, 0), "a driving robot's motors");
    z
}

#[test]
fn a_1200_baud_touch_stops_the_motors_stores_the_key_and_resets_by_the_watchdog() {
    let mut z = driving_zumo_on_usb();
    assert!(z.watchdog_resets().is_empty());
    assert_eq!(z.boot_key(), 0);
    z.usb_set_line_coding(1200).unwrap();
    assert_ne!(
        z.duties(),
        (0, 0),
        "1200 baud with DTR still high is no touch"
    );
    z.usb_set_dtr(false).unwrap();
    // Stopped in the USB service that acknowledged the request: by the time
    // the host has the acknowledgement.
    assert_eq!(z.duties(), (0, 0), "motors when the touch is acknowledged");
    assert_eq!(z.boot_key(), BOOT_KEY);
    // The watchdog (125 ms) resets the chip with the key in place: the
    // bootloader would stay in itself. Until then the motors stay stopped.
    // (`run_until_watchdog_reset`: the only stepping that crosses a reset)
    let mut ms = 0;
    loop {
        assert_eq!(z.duties(), (0, 0), "motors {ms} ms after the touch");
        assert!(ms < 400, "no watchdog reset within 400 ms of the touch");
        ms += 1;
        if z.run_until_watchdog_reset(1).is_some() {
            break;
        }
    }
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
    assert_eq!(z.usb_enumerate(9).device, DEVICE);
    assert_eq!(z.usb_address(), Some(9));
    z.usb_set_dtr(true).unwrap();
    frames_flow_again(&mut z, "the cable plugged back");
}

/// Suspend (USB 2.0 section 7.1.7.6: no bus activity for 3 ms): the
/// firmware freezes the controller's clock and turns the PLL off; the
/// robot drives and logs on TXD1 as before (`docs/firmware.md`, "USB
/// serial port"); the host's resume wakes the port with its address and
/// configuration, and frames come out whole again.
#[test]
fn a_suspended_bus_freezes_the_usb_clock_while_the_robot_drives_on_and_wakes_up() {
    let mut z = driving_zumo_on_usb();
    assert!(!z.usb_clock_frozen() && z.usb_pll_on());
    z.frames();
    z.suspend_usb(true);
    z.run_ms(1);
    assert!(z.usb_clock_frozen(), "suspended: the USB clock still runs");
    assert!(!z.usb_pll_on(), "suspended: the PLL still on");
    for ms in (0..100).step_by(10) {
        assert_ne!(z.duties(), (0, 0), "motors {ms} ms into the suspend");
        z.run_ms(10);
    }
    let frames: Vec<LogFrame> = z
        .frames()
        .into_iter()
        .map(|f| f.expect("a frame that does not decode"))
        .collect();
    assert!(
        frames.len() >= 4,
        "{} frames in 100 ms suspended",
        frames.len()
    );
    assert!(frames.windows(2).all(|w| w[1].tick == w[0].tick + 1));
    assert!(frames.iter().all(|f| f.mode == RunMode::Driving));
    assert!(z.usb_clock_frozen(), "still suspended");

    z.suspend_usb(false);
    z.run_ms(1);
    assert!(!z.usb_clock_frozen() && z.usb_pll_on(), "woken up");
    assert_eq!(z.usb_address(), Some(5));
    assert_eq!(z.usb_control(setup(0x80, 8, 0, 0, 1), &[]), Ok(vec![1]));
    assert_eq!(z.usb_line_coding().0, 115_200);
    frames_flow_again(&mut z, "the suspend");
}

/// SET_FEATURE(ENDPOINT_HALT) halts an endpoint: its transactions stall
/// and GET_STATUS says so; CLEAR_FEATURE(ENDPOINT_HALT) clears it (and
/// resets its data toggle, which simavr does not model) and the log flows
/// again, in whole frames (USB 2.0 sections 9.4.1, 9.4.5, 9.4.9). Features
/// the device does not have stall.
#[test]
fn a_halted_endpoint_stalls_until_the_host_clears_the_halt() {
    let mut z = open_port();
    z.run_ms(40);
    let status = |z: &mut Zumo, ep: u16| z.usb_control(setup(0x82, 0, 0, ep, 2), &[]);
    assert_eq!(status(&mut z, 0x83), Ok(vec![0, 0]));
    z.usb_control(setup(0x02, 3, 0, 0x83, 0), &[])
        .expect("SET_FEATURE(ENDPOINT_HALT) on 0x83");
    assert_eq!(status(&mut z, 0x83), Ok(vec![1, 0]));
    for _ in 0..5 {
        assert_eq!(z.usb_bulk_in(BULK_IN), Err(Stalled), "a halted bulk IN");
        z.run_ms(20);
    }
    z.usb_control(setup(0x02, 3, 0, 0x02, 0), &[])
        .expect("SET_FEATURE(ENDPOINT_HALT) on 0x02");
    assert_eq!(
        z.usb_out(BULK_OUT, b"hello"),
        Err(Stalled),
        "a halted bulk OUT"
    );
    // TXD1 lost nothing meanwhile.
    let ticks: Vec<u32> = z.frames().into_iter().map(|f| f.unwrap().tick).collect();
    assert!(ticks.len() >= 5 && ticks.windows(2).all(|w| w[1] == w[0] + 1));

    z.usb_control(setup(0x02, 1, 0, 0x83, 0), &[])
        .expect("CLEAR_FEATURE(ENDPOINT_HALT) on 0x83");
    z.usb_control(setup(0x02, 1, 0, 0x02, 0), &[])
        .expect("CLEAR_FEATURE(ENDPOINT_HALT) on 0x02");
    assert_eq!(status(&mut z, 0x83), Ok(vec![0, 0]));
    assert_eq!(z.usb_out(BULK_OUT, b"hello"), Ok(()));
    frames_flow_again(&mut z, "the halt");

    // An endpoint that does not exist, the wrong direction, remote wake-up
    // (the configuration says the device has none) and test mode stall.
    for request in [
        setup(0x02, 3, 0, 0x84, 0),
        setup(0x02, 3, 0, 0x03, 0),
        setup(0x82, 0, 0, 0x84, 2),
        setup(0x00, 3, 1, 0, 0),
        setup(0x00, 3, 2, 0x0100, 0),
    ] {
        assert_eq!(z.usb_control(request, &[]), Err(Stalled), "{request:02x?}");
    }
    assert_eq!(z.usb_line_coding().0, 115_200, "the port still answers");
}
