//! Firmware entry point: the control loop. On the host this binary is empty
//! so that the workspace builds; the AVR build is `scripts/build-firmware`.
//!
//! Each 20 ms period: encoder counts of the period before -> buttons -> field sensors (RC timing) -> Pixy blocks
//! -> supervisor (mode, faults) -> decision -> motors -> EEPROM (after a
//! calibration from the display's screens) -> LEDs -> log frame queued for USART1
//! and, when a host holds the USB serial port open, on USB. USB is served
//! while the loop waits (`board::usb`); after a 1200-baud touch the loop
//! only waits, motors stopped, for the watchdog to reset the chip into the
//! bootloader.
#![cfg_attr(target_arch = "avr", no_std)]
#![cfg_attr(target_arch = "avr", no_main)]
#![cfg_attr(target_arch = "avr", feature(asm_experimental_arch))]
#![cfg_attr(target_arch = "avr", feature(abi_avr_interrupt))]

#[cfg(target_arch = "avr")]
mod board;

// The sources' hash, in a section that is not loaded (`build.rs`).
#[cfg(target_arch = "avr")]
core::arch::global_asm!(include_str!(concat!(env!("OUT_DIR"), "/source_hash.s")));

#[cfg(target_arch = "avr")]
#[avr_device::entry]
fn main() -> ! {
    use firmware::calibration_record::{self, RECORD_LEN};
    use firmware::config::{CALIBRATION_EEPROM_ADDR, CAMERA, UNCALIBRATED};
    use firmware::decision::Decider;
    use firmware::embedded;
    use shared::LogFrame;

    let (mut board, scales) = board::Board::take();
    board.init();
    board.usb_init(embedded::USB_SERIAL);

    let mut record = [0u8; RECORD_LEN];
    board.eeprom_read(CALIBRATION_EEPROM_ADDR, &mut record);
    let stored = calibration_record::decode(&record).ok();
    let mut calibration = stored.unwrap_or(UNCALIBRATED);
    let policy = board::FlashPolicy;
    // The curves stay in place (static RAM): each period's decider borrows them.
    scales.calibrate(&calibration);
    let LoopState {
        supervisor,
        camera,
        frame,
        choice,
    } = loop_state(stored.is_some(), board::robot_id());
    // Frames since the log last carried the calibration in use: it goes out
    // in the first frame, after a new one takes effect, and every
    // `LogFrame::CALIBRATION_EVERY` frames (a counter: no 32-bit modulo).
    let mut since_calibration = LogFrame::CALIBRATION_EVERY - 1;
    let robot_id = board::robot_id();
    // odd ids are innies: only a role-aware policy tells them apart
    let role = shared::Role::of_robot_id(robot_id);

    board.watchdog_on();
    loop {
        board.wait_period();
        if board.touched() {
            continue;
        }
        board.mark(4);
        let encoder_counts = board.take_encoder_counts();
        let buttons = board.buttons();
        let times = board.field_sensors();
        let camera_ok = camera.acquire(&mut board).is_ok();
        let plan = supervisor.period(buttons, &times, camera_ok);

        let decider = Decider::new(
            scales,
            CAMERA,
            embedded::HASHER,
            role,
            &policy,
            embedded::MOTORS,
        );
        // A touch during this period already stopped the motors: keep them so.
        let source = if board.touched() {
            firmware::supervisor::MotorSource::Stop
        } else {
            plan.motors
        };
        let before = choice.state();
        let (decision, command) =
            decide_and_drive(&board, &decider, &times, camera.blocks(), source, choice);
        since_calibration = since_calibration.saturating_add(1);
        let logged_calibration = if since_calibration >= LogFrame::CALIBRATION_EVERY {
            since_calibration = 0;
            Some(calibration)
        } else {
            None
        };

        if let Some(new) = plan.save {
            board.eeprom_write(CALIBRATION_EEPROM_ADDR, &calibration_record::encode(&new));
            scales.calibrate(&new);
            calibration = new;
            since_calibration = LogFrame::CALIBRATION_EVERY - 1;
        }
        board.leds(plan.leds);
        let log = LogFrame {
            tick: supervisor.tick(),
            mode: plan.mode,
            faults: plan.faults,
            raw_times: times,
            values: decision.values,
            blobs: decision.blobs,
            blocks: camera.blocks().len() as u8,
            state: decision.state,
            action: decision.action,
            motors: command,
            calibration: logged_calibration,
            robot_id,
            encoder_counts,
            // the generator's state before the decision, when it drew
            choice: (choice.state() != before).then_some(before),
        };
        let n = log.encode(frame);
        let bytes = frame.get(..n).unwrap_or(&[]);
        board.send(bytes);
        board.send_usb(bytes);
        board.mark(3);
    }
}

/// The control loop's state across periods, in static RAM: on the stack
/// it made the loop's frame about 550 bytes deep, which left too little
/// room above the bootloader key at 0x0800 (docs/firmware.md, "Measured").
#[cfg(target_arch = "avr")]
struct LoopState {
    supervisor: firmware::supervisor::Supervisor,
    camera: firmware::camera::Camera,
    frame: [u8; shared::LogFrame::MAX_ENCODED_LEN],
    /// The robot's choice among a state's best actions (docs/state-hash.md).
    choice: shared::ChoiceRng,
}

#[cfg(target_arch = "avr")]
static mut LOOP_STATE: core::mem::MaybeUninit<LoopState> = core::mem::MaybeUninit::uninit();

/// Sets up the loop's state in place (out of line: its temporaries stay
/// out of the loop's frame). Called once.
#[cfg(target_arch = "avr")]
#[inline(never)]
fn loop_state(calibrated: bool, robot_id: u8) -> &'static mut LoopState {
    // SAFETY: called once, before the loop: the only reference ever made.
    unsafe {
        (*core::ptr::addr_of_mut!(LOOP_STATE)).write(LoopState {
            supervisor: firmware::supervisor::Supervisor::new(calibrated),
            camera: firmware::camera::Camera::new(),
            frame: [0; shared::LogFrame::MAX_ENCODED_LEN],
            choice: shared::ChoiceRng::for_robot(robot_id),
        })
    }
}

/// One decision and the motor writes, bracketed by the simulator's cycle
/// markers (GPIOR0 = 1, then 2). Out of line on purpose: in the control
/// loop's large stack frame, LLVM's AVR backend reaches locals with
/// `in r0, SREG; adiw r28, ..` sequences that can clobber a multiply's
/// result in r0 (a miscompilation seen here: the block loop's length);
/// a small frame needs no such sequences. `scripts/build-firmware` checks
/// the whole image for the pattern.
#[cfg(target_arch = "avr")]
#[inline(never)]
fn decide_and_drive(
    board: &board::Board,
    decider: &firmware::decision::Decider<'_, board::FlashPolicy>,
    times: &[u16; 3],
    blocks: &[shared::PixyBlock],
    source: firmware::supervisor::MotorSource,
    choice: &mut shared::ChoiceRng,
) -> (firmware::decision::Decision, shared::MotorCommand) {
    use firmware::supervisor::MotorSource;
    use shared::{DriveOutputs, MotorCommand};
    board.mark(1);
    let decision = decider.decide(times, blocks, choice);
    let (outputs, command) = match source {
        MotorSource::Policy => (decision.outputs, decision.command),
        MotorSource::Stop => (DriveOutputs::STOP, MotorCommand::default()),
    };
    board.set_motors(&outputs);
    board.mark(2);
    (decision, command)
}

/// Never reached from the control loop (the build reports whether the
/// linker kept it); stops the motors and halts.
#[cfg(target_arch = "avr")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    board::emergency_stop();
    loop {}
}

#[cfg(not(target_arch = "avr"))]
fn main() {}
