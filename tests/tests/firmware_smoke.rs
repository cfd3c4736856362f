//! Smoke tests of the firmware's release ELF in simavr (`scripts/build-firmware`
//! builds it; these tests fail, never skip, when it is missing).
//!
//! The emulated Zumo has RC-timed field sensors, a Pixy on TWI, wheel
//! encoders, buttons A and B; the tests read the motor duties from
//! OCR1A/OCR1B and decode the USART1 log frames with `shared`, and check
//! every decision against the same decision computed on the host.

use firmware::calibration_record;
use firmware::config::{CAMERA, PERIOD_TICKS, RC_TIMEOUT_TICKS};
use firmware::decision::Decider;
use firmware::embedded;
use shared::{Faults, FieldCalibration, LogFrame, MotorCommand, PixyBlock, RunMode, SensorRange};
use tests::zumo::{
    pixy_bytes, pixy_frame_words, Zumo, CYCLES_PER_TICK, PIXY_SYNC, PIXY_SYNC_SWAPPED, PUCK_LEFT,
};

const CALIBRATION: FieldCalibration = FieldCalibration {
    ranges: [SensorRange {
        bright: 40,
        dark: 440,
    }; 3],
};
/// Left 0.35, mid 0.6 (bin 9 of 16), right 0.725.
const SENSOR_TICKS: [Option<u16>; 3] = [Some(300), Some(200), Some(150)];
const ROBOT_RIGHT: PixyBlock = PixyBlock {
    signature: 2,
    x: 250,
    y: 180,
    width: 40,
    height: 30,
    angle: 0,
};
const BUDGET_CYCLES: u64 = 2_000;
/// The lowest address the stack may reach: 256 bytes above the bootloader
/// key (0x0800, two bytes).
const STACK_FLOOR: usize = 0x0802 + 256;
/// The bulk IN endpoint the log frames go out on.
const IN_EP: u8 = firmware::usb::IN_EP;

fn calibrated_zumo() -> Zumo {
    let mut z = Zumo::boot();
    z.write_eeprom(0, &calibration_record::encode(&CALIBRATION));
    z.set_sensor_ticks(SENSOR_TICKS);
    z
}

fn decoded(z: &mut Zumo) -> Vec<LogFrame> {
    let frames: Vec<LogFrame> = z
        .frames()
        .into_iter()
        .map(|f| f.unwrap_or_else(|e| panic!("undecodable log frame: {e}")))
        .collect();
    assert!(!frames.is_empty(), "no log frames on USART1");
    for pair in frames.windows(2) {
        assert_eq!(pair[1].tick, pair[0].tick + 1, "a log frame was lost");
    }
    frames
}

/// The frame's decision, recomputed on the host from its raw times.
fn check_decision(frame: &LogFrame, blocks: &[PixyBlock]) -> shared::DriveOutputs {
    let scales = CALIBRATION.scales();
    let decider = Decider::new(
        &scales,
        CAMERA,
        embedded::HASHER,
        shared::Role::Outie,
        &embedded::POLICY_SETS[..],
        embedded::MOTORS,
    );
    // the default policy has no ties: the robot never draws
    assert_eq!(frame.choice, None);
    let mut choice = shared::ChoiceRng::for_robot(frame.robot_id);
    let expected = decider.decide(&frame.raw_times, blocks, &mut choice);
    assert_eq!(frame.values, expected.values);
    assert_eq!(frame.blobs, expected.blobs);
    assert_eq!(frame.state, expected.state);
    assert_eq!(frame.action, expected.action);
    assert_eq!(frame.blocks as usize, blocks.len());
    expected.outputs
}

#[test]
fn boots_starts_with_button_a_reads_sensors_and_camera_and_drives() {
    let mut z = calibrated_zumo();
    z.show(&[PUCK_LEFT, ROBOT_RIGHT]);
    z.run_ms(1);
    z.paint_stack();
    z.run_ms(100);
    let idle = decoded(&mut z);
    let last = idle.last().unwrap();
    assert_eq!(
        (last.mode, last.faults, last.motors),
        (RunMode::Idle, Faults::NONE, MotorCommand::default())
    );
    assert_eq!(z.duties(), (0, 0));
    assert_ne!(
        z.boot_key(),
        0x7777,
        "the bootloader key must not be left at 0x0800"
    );

    z.press_a();
    z.run_ms(200);
    let frames = decoded(&mut z);
    let last = *frames.last().unwrap();
    assert_eq!((last.mode, last.faults), (RunMode::Driving, Faults::NONE));
    for (got, want) in last.raw_times.iter().zip(SENSOR_TICKS) {
        let want = want.unwrap();
        assert!(
            got.abs_diff(want) <= 2,
            "raw times {:?}, emulated {SENSOR_TICKS:?}",
            last.raw_times
        );
    }
    assert!(last.blobs.puck_left && !last.blobs.puck_right && last.blobs.obstacle_right);
    let outputs = check_decision(&last, &[PUCK_LEFT, ROBOT_RIGHT]);
    assert_eq!(last.motors, embedded::MOTORS.commands[last.action.index()]);
    assert_eq!(z.duties(), (outputs.left.duty, outputs.right.duty));
    assert!(z.duties() != (0, 0));

    let cycles = z.decision_cycles();
    let worst = *cycles.iter().max().expect("no decision markers seen");
    println!(
        "decision cycles over {} decisions: min {}, max {worst}",
        cycles.len(),
        cycles.iter().min().unwrap()
    );
    assert!(
        worst <= BUDGET_CYCLES,
        "a decision took {worst} cycles, budget {BUDGET_CYCLES}"
    );

    // The stack stays at least 256 bytes above the bootloader key at
    // 0x0800 (the firmware clears it at start-up; only the 1200-baud touch
    // writes it).
    let low = z.stack_low_water();
    println!(
        "stack low water {low:#06x}: {} bytes of stack",
        0x0B00 - low
    );
    assert!(
        low >= STACK_FLOOR,
        "the stack reached {low:#06x}, less than 256 bytes above the bootloader key at 0x0800"
    );

    // A again stops.
    z.press_a();
    z.run_ms(60);
    assert_eq!(decoded(&mut z).last().unwrap().mode, RunMode::Idle);
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn without_a_calibration_it_reports_and_does_not_drive() {
    let mut z = Zumo::boot();
    z.run_ms(60);
    z.press_a();
    z.run_ms(100);
    for f in decoded(&mut z) {
        assert!(f.faults.contains(Faults::NO_CALIBRATION));
        assert_eq!((f.mode, f.motors), (RunMode::Idle, MotorCommand::default()));
    }
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn a_corrupt_calibration_is_refused_and_the_robot_does_not_drive() {
    let mut record = calibration_record::encode(&CALIBRATION);
    record[3] ^= 0x10;
    let mut z = Zumo::boot();
    z.write_eeprom(0, &record);
    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(60);
    z.press_a();
    z.run_ms(100);
    for f in decoded(&mut z) {
        assert!(f.faults.contains(Faults::NO_CALIBRATION), "{f:?}");
        assert_eq!((f.mode, f.motors), (RunMode::Idle, MotorCommand::default()));
    }
    assert_eq!(z.duties(), (0, 0));
}

#[test]
fn a_silent_camera_or_blind_sensors_stop_the_motors_until_readings_return() {
    let mut z = calibrated_zumo();
    z.run_ms(40);
    z.press_a();
    z.run_ms(60);
    assert!(z.duties() != (0, 0));

    z.connect_pixy(false);
    z.run_ms(120);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(
        (last.mode, last.faults, last.motors),
        (
            RunMode::Driving,
            Faults::CAMERA_SILENT,
            MotorCommand::default()
        )
    );
    assert_eq!(z.duties(), (0, 0));

    z.connect_pixy(true);
    z.run_ms(60);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.faults, Faults::NONE);
    let outputs = check_decision(&last, &[]);
    assert_eq!(z.duties(), (outputs.left.duty, outputs.right.duty));

    z.set_sensor_ticks([None; 3]);
    z.run_ms(120);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.raw_times, [RC_TIMEOUT_TICKS; 3]);
    assert_eq!(
        (last.faults, last.motors),
        (Faults::SENSORS_TIMEOUT, MotorCommand::default())
    );
    assert_eq!(z.duties(), (0, 0));

    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(60);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.faults, Faults::NONE);
    assert!(z.duties() != (0, 0));
}

#[test]
fn button_b_then_the_white_and_black_screens_store_each_sensors_readings_standing_still() {
    let mut z = Zumo::boot();
    z.run_ms(40);
    // The display shows the field, then white, then black (`host display`'s sequence).
    z.set_sensor_ticks([Some(250), Some(300), Some(200)]);
    z.press_b();
    z.run_ms(200);
    z.calibrate_ticks(
        [Some(38), Some(40), Some(43)],
        [Some(425), Some(440), Some(455)],
    );
    let frames = decoded(&mut z);
    let calibrating: Vec<_> = frames
        .iter()
        .filter(|f| f.mode == RunMode::Calibrating)
        .collect();
    assert!(
        calibrating.len() >= 2 * firmware::screen_calibration::WINDOW,
        "{} calibrating frames",
        calibrating.len()
    );
    assert!(
        calibrating
            .iter()
            .all(|f| f.motors == MotorCommand::default()),
        "the robot must stand still"
    );
    let last = frames.last().unwrap();
    assert_eq!((last.mode, last.faults), (RunMode::Idle, Faults::NONE));

    let stored = calibration_record::decode(&z.read_eeprom(0, 16).try_into().unwrap())
        .expect("a stored calibration");
    // Each reading is the screen's time, to the tick the poll loop reads it in
    // (`docs/equivalence.md` checks it exactly, from mid-tick stimuli).
    for (range, want) in stored.ranges.iter().zip([(38, 425), (40, 440), (43, 455)]) {
        assert!(
            range.bright.abs_diff(want.0) <= 1 && range.dark.abs_diff(want.1) <= 1,
            "{stored:?}"
        );
    }
    // The log carries the new calibration in the frame after it took effect.
    assert_eq!(
        frames.iter().rev().find_map(|f| f.calibration),
        Some(stored)
    );

    z.set_sensor_ticks(SENSOR_TICKS);
    z.press_a();
    z.run_ms(40);
    assert_eq!(decoded(&mut z).last().unwrap().mode, RunMode::Driving);
    assert!(z.duties() != (0, 0));
}

#[test]
fn a_calibration_that_never_sees_white_then_black_fails_and_keeps_the_old_one() {
    let mut z = calibrated_zumo();
    z.run_ms(40);
    // Armed while black already shows, then the field: no white-then-black.
    z.set_sensor_ticks([Some(425), Some(440), Some(455)]);
    z.press_b();
    z.run_ms(300);
    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(300);
    assert_eq!(decoded(&mut z).last().unwrap().mode, RunMode::Calibrating);
    z.press_a(); // A aborts
    z.run_ms(40);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!((last.mode, last.faults), (RunMode::Idle, Faults::NONE));
    let stored = calibration_record::decode(&z.read_eeprom(0, 16).try_into().unwrap());
    assert_eq!(stored, Ok(CALIBRATION));
}

#[test]
fn encoder_edges_are_counted_per_period_in_the_log_and_the_robot_id_with_them() {
    let mut z = calibrated_zumo();
    z.run_ms(40);
    decoded(&mut z);
    // Left forward at 3,000 counts/s, right backwards at 1,250 (60 and -25 per period).
    z.set_wheel_counts_per_second([3_000, -1_250]);
    z.run_ms(400);
    z.set_wheel_counts_per_second([0, 0]);
    z.run_ms(60);
    let frames = decoded(&mut z);
    let logged = frames.iter().fold([0i64; 2], |acc, f| {
        [
            acc[0] + i64::from(f.encoder_counts[0]),
            acc[1] + i64::from(f.encoder_counts[1]),
        ]
    });
    let counts: Vec<[i16; 2]> = frames.iter().map(|f| f.encoder_counts).collect();
    assert_eq!(
        logged,
        z.encoder_steps(),
        "every edge counted once, with its sign: {counts:?}"
    );
    assert_eq!(z.encoder_steps(), [1_200, -500]);
    let steady: Vec<[i16; 2]> = frames
        .iter()
        .map(|f| f.encoder_counts)
        .filter(|c| c[0] != 0)
        .collect();
    assert!(
        steady.iter().filter(|c| **c == [60, -25]).count() >= 15,
        "{steady:?}"
    );
    assert!(
        frames.iter().all(|f| f.robot_id == 0),
        "the default build has robot id 0"
    );
}

/// The USB serial port open and streaming to a host that reads it all
/// and sends a control request (GET_DESCRIPTOR, two packets) every 7 ms,
/// so that requests arrive anywhere in the control period.
fn usb_streaming(z: &mut Zumo) {
    z.usb_open(2);
    z.stream_usb_in_background(IN_EP, 7_000);
}

/// 400 ms of the heaviest periods: driving, both wheels at 6,000 counts/s
/// (about 0.8 m/s on 75:1 motors, faster than a Zumo drives), the sensors
/// near their timeout, and frames of eight colour-code blocks; with the
/// USB port streaming ([`usb_streaming`]) or no cable.
/// What [`heaviest_periods_of`] over 1.1 s measured in its driving periods.
struct LongRun {
    /// One decision's cycles, fewest and most.
    decisions: (u64, u64),
    /// The heaviest period's work, in cycles.
    work: u64,
    /// That period's sensing (start to decision), decision, and logging
    /// (decision's end to the log frame's end), in cycles.
    split: [u64; 3],
    /// That period's log frame, bytes with its delimiter.
    frame_len: usize,
    /// The stack's lowest address.
    low: usize,
}

fn heaviest_periods(usb: bool) -> Zumo {
    heaviest_periods_of(
        Zumo::boot(),
        &CALIBRATION,
        [Some(490), Some(495), Some(499)],
        usb,
        400,
    )
}

/// The heaviest periods ([`heaviest_periods`]) of the firmware booted in
/// `z`, calibrated with `calibration`, the sensors at `ticks`, for `ms`;
/// the stack painted from the start.
fn heaviest_periods_of(
    mut z: Zumo,
    calibration: &FieldCalibration,
    ticks: [Option<u16>; 3],
    usb: bool,
    ms: u64,
) -> Zumo {
    z.write_eeprom(0, &calibration_record::encode(calibration));
    z.set_sensor_ticks(SENSOR_TICKS);
    z.run_ms(1);
    z.paint_stack();
    z.run_ms(39);
    if usb {
        usb_streaming(&mut z);
    }
    z.press_a();
    z.set_wheel_counts_per_second([6_000, 6_000]);
    z.set_sensor_ticks(ticks);
    let cc = |i: u16| PixyBlock {
        signature: 0o12,
        x: 10 + 30 * i,
        y: 150,
        width: 20,
        height: 20,
        angle: -45,
    };
    z.show(&(0..8).map(cc).collect::<Vec<_>>());
    z.run_ms(ms);
    z
}

#[test]
fn odometry_at_full_speed_and_the_largest_frames_do_not_delay_the_control_period() {
    let mut z = heaviest_periods(true);
    let frames = decoded(&mut z);
    let last = frames.last().unwrap();
    // Eight blocks in view: never more than four read (which periods get
    // them depends on where the Pixy's 20 ms frames fall in the period).
    assert!(frames.iter().all(|f| f.blocks <= 4) && frames.iter().any(|f| f.blocks == 4));
    assert!(
        last.encoder_counts.iter().all(|c| (119..=121).contains(c)),
        "{:?}",
        last.encoder_counts
    );
    let period = u64::from(PERIOD_TICKS) * CYCLES_PER_TICK;
    let periods = z.period_cycles();
    assert!(periods.len() >= 20);
    // Each period starts on time, within what the two wheels' encoder
    // interrupts (about 65 cycles each with their entry and exit, and at
    // 6,000 counts/s they can fall together) shift the poll of the timer.
    assert!(
        periods
            .iter()
            .all(|p| p.abs_diff(period) < 3 * CYCLES_PER_TICK),
        "periods (cycles): {periods:?}"
    );
    let work = *z.period_work_cycles().iter().max().unwrap();
    println!("period work, odometry at 6,000 counts/s, 8 colour-code blocks, sensors near timeout: {work} of {period} cycles");
    assert!(
        work < period,
        "a period's work took {work} cycles, longer than the period"
    );
    let worst = *z.decision_cycles().iter().max().unwrap();
    assert!(
        worst <= BUDGET_CYCLES,
        "a decision took {worst} cycles with the encoders running"
    );
}

#[test]
fn colour_codes_garbage_resync_words_and_long_frames_are_read_as_the_pixy_means_them() {
    let mut z = calibrated_zumo();
    z.run_ms(40);
    z.press_a();
    z.run_ms(60);
    // A colour-code puck on the left (signature 0o12 is not a puck: it is ignored
    // unless configured), a normal robot block, more blocks than the firmware reads.
    let cc_robot = PixyBlock {
        signature: 0o12,
        x: 280,
        y: 170,
        width: 30,
        height: 30,
        angle: 90,
    };
    let many: Vec<PixyBlock> = [PUCK_LEFT, cc_robot, ROBOT_RIGHT]
        .into_iter()
        .chain((0..5).map(|i| PixyBlock {
            signature: 1,
            x: 300,
            y: 120 + i,
            width: 5,
            height: 5,
            angle: 0,
        }))
        .collect();
    let first_four = &many[..4];
    // Garbage, then an odd byte: the syncs that follow read one byte off (0x55AA)
    // until the firmware skips a byte; then the frame.
    let mut bytes = pixy_bytes(&[0x1234, 0xBEEF, PIXY_SYNC, 0x0042]);
    bytes.push(0x77);
    bytes.extend(pixy_bytes(&[PIXY_SYNC, PIXY_SYNC]));
    bytes.extend(pixy_bytes(&pixy_frame_words(&many)));
    z.show_bytes(&bytes);
    z.run_ms(100);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!(last.faults, Faults::NONE);
    assert_eq!(last.blocks, 4, "the first four blocks of the frame");
    check_decision(&last, first_four);
    assert_eq!(
        u16::from_le_bytes([bytes[10], bytes[11]]),
        PIXY_SYNC_SWAPPED,
        "the test serves a misaligned sync"
    );

    // A block with a bad checksum is dropped; the rest of the frame is used.
    let mut words = pixy_frame_words(&[PUCK_LEFT, ROBOT_RIGHT]);
    words[2] ^= 1;
    z.show_bytes(&pixy_bytes(&words));
    z.run_ms(100);
    let last = *decoded(&mut z).last().unwrap();
    check_decision(&last, &[ROBOT_RIGHT]);
}

#[test]
fn a_device_holding_sda_low_is_clocked_free_and_the_camera_reads_again() {
    let mut z = calibrated_zumo();
    z.show(&[PUCK_LEFT]);
    z.run_ms(60);
    z.press_a();
    z.run_ms(60);
    // Cut off mid-byte: it lets go after 3 more clocks.
    z.hold_sda_low(Some(3));
    z.run_ms(100);
    assert!(!z.sda_held());
    assert_eq!(z.scl_clocks_while_sda_held(), 3);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!((last.faults, last.blocks), (Faults::NONE, 1));
    check_decision(&last, &[PUCK_LEFT]);

    // Held for ever: the camera is silent, the loop keeps its period, the motors stop.
    z.hold_sda_low(None);
    z.run_ms(120);
    let frames = decoded(&mut z);
    assert_eq!(frames.last().unwrap().faults, Faults::CAMERA_SILENT);
    assert_eq!(z.duties(), (0, 0));
    assert!(
        z.scl_clocks_while_sda_held() >= 9,
        "the firmware clocks SCL to free the bus"
    );
    let period = u64::from(PERIOD_TICKS) * CYCLES_PER_TICK;
    assert!(
        z.period_cycles()
            .iter()
            .rev()
            .take(5)
            .all(|p| p.abs_diff(period) < CYCLES_PER_TICK),
        "{:?}",
        z.period_cycles()
    );
    z.hold_sda_low(Some(1));
    z.run_ms(60);
    let last = *decoded(&mut z).last().unwrap();
    assert_eq!((last.faults, last.blocks), (Faults::NONE, 1));
}

/// Flash (.text + .data) and static RAM (.data + .bss) of an ELF, from `avr-size -B`.
fn sizes(elf: &std::path::Path) -> (u64, u64) {
    let out = std::process::Command::new("avr-size")
        .arg("-B")
        .arg(elf)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run avr-size ({e}): install binutils-avr (`scripts/setup`)")
        });
    let text = String::from_utf8_lossy(&out.stdout);
    let n: Vec<u64> = text
        .lines()
        .nth(1)
        .unwrap_or("")
        .split_whitespace()
        .take(3)
        .filter_map(|v| v.parse().ok())
        .collect();
    assert_eq!(n.len(), 3, "avr-size output: {text}");
    (n[0] + n[1], n[1] + n[2])
}

/// The flash below the A-Star bootloader, which starts at 0x7000
/// (`../shared/docs/hardware.md` section 6).
const FLASH_BUDGET: u64 = 0x7000;
/// Static RAM (.data + .bss from 0x0100): the statics end by 0x0700,
/// below the bootloader key at 0x0800, and leave the stack the top 1,024
/// of the 2,560 bytes.
const RAM_BUDGET: u64 = 1_536;

/// Every image the simavr tests run (the default and the equivalence
/// tests' variants, `scripts/test` builds them all) fits the flash below
/// the bootloader and the static RAM budget: what `scripts/build-firmware`
/// checks when it builds, checked again on the ELFs the tests run.
#[test]
fn every_image_fits_the_flash_below_the_bootloader_and_the_static_ram_budget() {
    use tests::equivalence::{EIGHT_BIT, GENERAL, ROLE, SEARCH_ANNULUS, SEARCH_T, TEN_BIT, TIED};
    use tests::zumo::{firmware_elf, firmware_elf_in};
    let mut images = vec![firmware_elf()];
    for v in [
        EIGHT_BIT,
        TEN_BIT,
        ROLE,
        TIED,
        SEARCH_ANNULUS,
        GENERAL,
        SEARCH_T,
    ] {
        images.push(firmware_elf_in(v.elf_dir, v.build));
    }
    for elf in images {
        let (flash, ram) = sizes(&elf);
        println!("{}: flash {flash}, static RAM {ram}", elf.display());
        assert!(
            flash <= FLASH_BUDGET,
            "{}: {flash} bytes of flash, over the {FLASH_BUDGET} below the bootloader",
            elf.display()
        );
        assert!(
            ram <= RAM_BUDGET,
            "{}: {ram} bytes of static RAM, over the budget of {RAM_BUDGET}",
            elf.display()
        );
    }
}

/// USB's share of an ELF: flash (code and flash-initialised data) and
/// static RAM of the symbols of `board::usb` and `firmware::usb` and of
/// `Board::serve_usb` (which inlines the port's work), from `avr-nm -S`.
fn usb_sizes(elf: &std::path::Path) -> (u64, u64) {
    let out = std::process::Command::new("avr-nm")
        .args(["-S", "--size-sort"])
        .arg(elf)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run avr-nm ({e}): install binutils-avr (`scripts/setup`)")
        });
    let (mut flash, mut ram) = (0, 0);
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let [_, size, kind, name] = f[..] else {
            continue;
        };
        // Rust's v0 mangling: `..5board3usb..`, `..8firmware3usb..`, `..9serve_usb`.
        if !(name.contains("5board3usb")
            || name.contains("8firmware3usb")
            || name.contains("9serve_usb"))
        {
            continue;
        }
        let size = u64::from_str_radix(size, 16).unwrap_or(0);
        match kind {
            "t" | "T" => flash += size,
            "d" | "D" => {
                flash += size;
                ram += size;
            }
            "b" | "B" => ram += size,
            _ => {}
        }
    }
    assert!(flash > 0 && ram > 0, "no USB symbols in {}", elf.display());
    (flash, ram)
}

#[test]
fn the_figures_in_docs_firmware_md_are_the_ones_measured() {
    use shared::PolicyBlob;
    use tests::equivalence::TIED;
    use tests::figures::{compiler_of, thousands, workspace, Figures};
    use tests::zumo::{firmware_elf, firmware_elf_in};
    const REGENERATE: &str = "UPDATE_FIGURES=1 cargo test -p tests --test firmware_smoke figures";
    let elf = firmware_elf();
    let mut figures = Figures::new(&compiler_of(&elf));
    figures.fixed(&[
        "log frame, longest",
        &format!("{} bytes", LogFrame::MAX_ENCODED_LEN),
        "-",
        "`shared::LogFrame::MAX_ENCODED_LEN`",
    ]);

    let build = "scripts/test (or scripts/build-firmware with FIRMWARE_OUT, docs/equivalence.md)";
    let (flash, ram) = sizes(&elf);
    let (flash10, _) = sizes(&firmware_elf_in("robot-annulus-10bit", build));
    let (usb_flash, usb_ram) = usb_sizes(&elf);
    figures.compiled(&[
        "flash (.text + .data)",
        &format!(
            "{} bytes (10-bit policy: {}); USB's code and descriptors {}",
            thousands(flash),
            thousands(flash10),
            thousands(usb_flash)
        ),
        "28,672",
        "`scripts/build-firmware` (avr-size -B); USB: `avr-nm -S`, the symbols of `board::usb`, `firmware::usb` and `Board::serve_usb`",
    ]);
    figures.compiled(&[
        "static RAM (.data + .bss)",
        &format!(
            "{} bytes; USB's port and descriptors {}",
            thousands(ram),
            thousands(usb_ram)
        ),
        "1,536",
        "`scripts/build-firmware`; USB: as above",
    ]);

    // Driving with the camera and sensors busy: decisions and the stack,
    // with no cable, then with USB streaming and control requests.
    let driving = |usb: bool| {
        let mut z = calibrated_zumo();
        z.show(&[PUCK_LEFT, ROBOT_RIGHT]);
        z.run_ms(1);
        z.paint_stack();
        if usb {
            usb_streaming(&mut z);
        }
        z.run_ms(40);
        z.press_a();
        z.run_ms(300);
        if usb {
            assert!(z.usb_background().1 > 0, "no control request answered");
        }
        (z.decision_cycles(), z.stack_low_water())
    };
    let (quiet_cycles, quiet_low) = driving(false);
    let (cycles, low) = driving(true);
    assert!(
        low >= STACK_FLOOR && quiet_low >= STACK_FLOOR,
        "the stack reached {:#06x}: less than 256 bytes above the bootloader key",
        low.min(quiet_low)
    );
    figures.compiled(&[
        "stack, deepest (USB streaming)",
        &format!(
            "{} bytes (down to {low:#06X}, {} bytes above the key); no cable: {} bytes",
            0x0B00 - low,
            low - 0x0802,
            0x0B00 - quiet_low
        ),
        "256 bytes above the key (down to 0x0902)",
        "this test",
    ]);
    let span = |c: &[u64]| {
        format!(
            "{} to {}",
            thousands(*c.iter().min().unwrap()),
            thousands(*c.iter().max().unwrap())
        )
    };
    figures.compiled(&[
        "one decision (this test's driving run, USB streaming)",
        &format!(
            "{} cycles; no cable: {}",
            span(&cycles),
            span(&quiet_cycles)
        ),
        "2,000",
        "this test; over the trained policies: `docs/equivalence.md`",
    ]);

    // The heaviest period: odometry at 6,000 counts/s per wheel, eight
    // colour-code blocks, sensors near timeout; USB streaming, then no cable.
    let heaviest = |usb: bool| {
        let mut z = heaviest_periods(usb);
        decoded(&mut z);
        let (_, requests, wait) = z.usb_background();
        assert!(!usb || requests > 0, "no control request answered");
        (*z.period_work_cycles().iter().max().unwrap(), wait)
    };
    let (work, wait) = heaviest(true);
    let (quiet_work, _) = heaviest(false);
    // A control request waits at most for the RC timing and a decision
    // (never served there), plus the host's 100 us between visits.
    assert!(wait <= 2_600 * 16, "a control request waited {wait} cycles");
    figures.compiled(&[
        "a control request's wait for its answer, longest (the heaviest periods, a request every 7 ms)",
        &format!("{} us", thousands(wait / 16)),
        "50 ms (USB 2.0, 9.2.6.4)",
        "this test (the host looks every 100 us)",
    ]);
    let period = u64::from(PERIOD_TICKS) * CYCLES_PER_TICK;
    assert!(
        work <= period && quiet_work <= period,
        "the heaviest period's work, {work} cycles with USB and {quiet_work} without, overruns {period}"
    );
    figures.compiled(&[
        "a period's work, heaviest (odometry at 6,000 counts/s, 4 colour-code blocks read, sensors near timeout; USB streaming, a control request every 7 ms)",
        &format!(
            "{} cycles ({:.1} ms); no cable: {} ({:.1} ms)",
            thousands(work),
            work as f64 / 16_000.0,
            thousands(quiet_work),
            quiet_work as f64 / 16_000.0
        ),
        &format!("{} (20 ms)", thousands(period)),
        "this test",
    ]);

    // The tied policy's firmware (robot 3) in the heaviest periods, every
    // period drawing among four best actions: the right sensor's time at
    // 499 ticks as in the heaviest periods (the RC poll lasts until the
    // last pin), the others the latest times whose state has four best
    // actions and keeps it when the left or mid time moves by up to 4 ticks
    // (at 6,000 counts/s the encoders' interrupts delay some polls by a few
    // ticks).
    let tied_elf = firmware_elf_in(TIED.elf_dir, TIED.build);
    let tied =
        PolicyBlob::decode(&std::fs::read(workspace().join("policies").join(TIED.policy)).unwrap())
            .unwrap();
    let (tied_flash, tied_ram) = sizes(&tied_elf);
    let scales = CALIBRATION.scales();
    let state_of = |t: [u16; 3]| {
        let reading = shared::SensorReading::from_parts(scales.values(&t), CAMERA.classify(&[]));
        TIED.hasher
            .hash_as(&reading, shared::Role::of_robot_id(TIED.robot_id))
    };
    let four = |t: [u16; 3]| {
        let s = state_of(t);
        let steady = (0..2).all(|i| {
            (t[i] - 4..=t[i] + 4).all(|v| {
                let mut m = t;
                m[i] = v;
                state_of(m) == s
            })
        });
        (steady && tied.sets().mask(s).count_ones() == 4).then_some(s)
    };
    let (drawing_ticks, drawing_state) = (40..=440u16)
        .rev()
        .flat_map(|mid| (40..=490u16).rev().map(move |left| [left, mid, 499]))
        .find_map(|t| four(t).map(|s| (t, s)))
        .expect("times near the timeout in a state with four best actions");
    // 1.1 s of the heaviest periods, so that a frame carrying the
    // calibration (every 50th) falls among them: the longest frames. With
    // `draws`, every driving period must draw in that state.
    let long_run =
        |elf: &std::path::Path, ticks: [u16; 3], draws: Option<shared::State>, usb: bool| {
            let mut z = heaviest_periods_of(
                Zumo::boot_elf(elf),
                &CALIBRATION,
                ticks.map(Some),
                usb,
                1_100,
            );
            let frames = decoded(&mut z);
            let driving: Vec<usize> = (0..frames.len())
                .filter(|&i| frames[i].mode == RunMode::Driving)
                .collect();
            assert!(driving.len() >= 50, "{} periods driving", driving.len());
            // the first driving periods read the times from before A was
            // pressed (the right one 150 ticks, not 499)
            let stale = |i: &&usize| frames[**i].raw_times[2] < 490;
            for &i in driving.iter().skip_while(stale).filter(|_| draws.is_some()) {
                let f = &frames[i];
                assert_eq!(
                    (Some(f.state), f.choice.is_some()),
                    (draws, true),
                    "period {}: every period draws among four (times {ticks:?}, read {:?})",
                    f.tick,
                    f.raw_times
                );
            }
            assert!(
                driving.iter().any(|&i| frames[i].calibration.is_some()),
                "no driving frame carried the calibration (the longest frames)"
            );
            if usb {
                assert!(z.usb_background().1 > 0, "no control request answered");
            }
            // period i's spans are the i-th marker spans since boot
            let (decisions, work) = (z.decision_cycles(), z.period_work_cycles());
            let (sensing, logging) = (z.sensing_cycles(), z.logging_cycles());
            assert!([&decisions, &work, &sensing, &logging]
                .iter()
                .all(|spans| spans.len() >= frames.len()));
            let heaviest = *driving.iter().max_by_key(|&&i| work[i]).unwrap();
            LongRun {
                decisions: (
                    driving.iter().map(|&i| decisions[i]).min().unwrap(),
                    driving.iter().map(|&i| decisions[i]).max().unwrap(),
                ),
                work: work[heaviest],
                split: [sensing[heaviest], decisions[heaviest], logging[heaviest]],
                frame_len: frames[heaviest].encode(&mut [0; LogFrame::MAX_ENCODED_LEN]),
                low: z.stack_low_water(),
            }
        };
    let drawing = |usb: bool| long_run(&tied_elf, drawing_ticks, Some(drawing_state), usb);
    let (loud, quiet) = (drawing(true), drawing(false));
    let default_long = long_run(&elf, [490, 495, 499], None, true);
    let (draw_min, draw_max, draw_work, draw_low) =
        (loud.decisions.0, loud.decisions.1, loud.work, loud.low);
    let (quiet_draw_min, quiet_draw_max, quiet_draw_work, quiet_draw_low) =
        (quiet.decisions.0, quiet.decisions.1, quiet.work, quiet.low);
    assert!(
        draw_max <= BUDGET_CYCLES && quiet_draw_max <= BUDGET_CYCLES,
        "a decision with a draw took {draw_max} cycles"
    );
    // The period budget holds with USB streaming and without a cable, a
    // draw in every period or none: any overrun fails.
    assert!(
        quiet_draw_work <= period,
        "the heaviest period with a draw took {quiet_draw_work} cycles without a cable, of {period}"
    );
    assert!(
        draw_work.max(default_long.work) <= period,
        "the heaviest period took {draw_work} cycles with a draw and {} without, with USB, of {period}",
        default_long.work
    );
    assert!(
        draw_low >= STACK_FLOOR && quiet_draw_low >= STACK_FLOOR,
        "drawing, the stack reached {:#06x}: less than 256 bytes above the bootloader key",
        draw_low.min(quiet_draw_low)
    );
    let against = |work: u64| {
        if work <= period {
            format!("within by {}", thousands(period - work))
        } else {
            format!("OVER by {}", thousands(work - period))
        }
    };
    figures.compiled(&[
        "tied policy (`robot-annulus-8bit-tied`, robot 3): flash, static RAM",
        &format!(
            "{} bytes, {} bytes",
            thousands(tied_flash),
            thousands(tied_ram)
        ),
        "28,672; 1,536",
        "`scripts/build-firmware`",
    ]);
    figures.compiled(&[
        "one decision with a draw among four tied actions (tied policy, the heaviest periods, USB streaming)",
        &format!(
            "{} to {} cycles; no cable: {} to {}",
            thousands(draw_min),
            thousands(draw_max),
            thousands(quiet_draw_min),
            thousands(quiet_draw_max)
        ),
        "2,000",
        "this test",
    ]);
    figures.compiled(&[
        "a period's work, heaviest over 1.1 s (the heaviest periods and a frame carrying the calibration), a draw among four in every period (tied policy; USB streaming)",
        &format!(
            "{} cycles ({:.1} ms, {}: sensors and camera {}, decision {}, log frame of {} bytes {}); no cable: {} ({:.1} ms, {}: {}, {}, {} bytes {})",
            thousands(draw_work),
            draw_work as f64 / 16_000.0,
            against(draw_work),
            thousands(loud.split[0]),
            thousands(loud.split[1]),
            loud.frame_len,
            thousands(loud.split[2]),
            thousands(quiet_draw_work),
            quiet_draw_work as f64 / 16_000.0,
            against(quiet_draw_work),
            thousands(quiet.split[0]),
            thousands(quiet.split[1]),
            quiet.frame_len,
            thousands(quiet.split[2])
        ),
        &format!("{} (20 ms)", thousands(period)),
        "this test",
    ]);
    figures.compiled(&[
        "the same over 1.1 s, default policy (no draw; USB streaming)",
        &format!(
            "{} cycles ({:.1} ms, {}: sensors and camera {}, decision {}, log frame of {} bytes {})",
            thousands(default_long.work),
            default_long.work as f64 / 16_000.0,
            against(default_long.work),
            thousands(default_long.split[0]),
            thousands(default_long.split[1]),
            default_long.frame_len,
            thousands(default_long.split[2])
        ),
        &format!("{} (20 ms)", thousands(period)),
        "this test",
    ]);
    figures.compiled(&[
        "stack, deepest, drawing in the heaviest periods (tied policy; USB streaming)",
        &format!(
            "{} bytes (down to {draw_low:#06X}, {} bytes above the key); no cable: {} bytes",
            0x0B00 - draw_low,
            draw_low - 0x0802,
            0x0B00 - quiet_draw_low
        ),
        "256 bytes above the key (down to 0x0902)",
        "this test",
    ]);

    match figures.check(
        "docs/firmware.md",
        "firmware",
        &["figure", "value", "budget", "measured by"],
        REGENERATE,
    ) {
        Ok(_) => {}
        Err(e) => panic!("{e:#}"),
    }
}
