//! The firmware ELF running in simavr, wired like a Zumo 32U4 on a field:
//! RC-timed field sensors (which check that the firmware's pull-ups are off
//! while they discharge), a Pixy on TWI (its frames encoded here, from the
//! Pixy's protocol, not by the firmware's code), wheel encoders, the I2C
//! lines' pull-ups (and a device that can hold SDA low), buttons, motor
//! registers, the USART1 log and the firmware's cycle markers (the USB
//! host is `crate::usb_host`).
//!
//! `avr-tester` runs the simulation; what it does not offer (USART1 on the
//! 32U4, data memory, the cycle counter, EEPROM, I/O register hooks) goes
//! through simavr's own handle (`simavr-ffi`): simavr passes the new core to
//! the global logger when `avr-tester` loads an ELF, and avr-tester installs
//! its own logger at its first load only, so ours, installed after a first
//! throwaway load, catches every later core's handle (see `load`).

use avr_tester::{AvrTester, TwiPacket};
use firmware::config::{PERIOD_TICKS, USB_QUIET_TICKS};
use firmware::pins::{self, Pin, Port, PIXY_ADDRESS};
use shared::{LogError, LogFrame, PixyBlock};
use simavr_ffi as ffi;
use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::ffi::c_void;
use std::os::raw::{c_char, c_int};
use std::path::{Path, PathBuf};
use std::ptr::null_mut;
use std::rc::Rc;
use std::sync::Once;

/// Simulated clock, Hz.
pub const CLOCK_HZ: u64 = 16_000_000;
/// Cycles per Timer3 tick (clk/64): the firmware's RC time unit.
pub const CYCLES_PER_TICK: u64 = 64;
/// OCR1A (right motor duty) in data memory.
const OCR1A: usize = 0x88;
/// OCR1B (left motor duty) in data memory.
const OCR1B: usize = 0x8A;
/// PORTB in data memory: the direction pins.
const PORTB: usize = 0x25;
/// GPIOR0, the firmware's decision marker, in data memory.
const GPIOR0: u16 = 0x3E;
/// MCUSR (reset flags) in data memory.
const MCUSR: u16 = 0x54;
/// The stack pointer (SPL, SPH) in data memory.
const SP: usize = 0x5D;
/// Above the firmware's statics at their budget (0x0100 + 1,536 bytes of .data + .bss).
const STATICS_END: usize = 0x0700;
/// One past the last SRAM byte.
const RAM_END: usize = 0x0B00;
/// The stack paint pattern.
const PAINT: u8 = 0xA5;
/// PORTD and PORTF in data memory: the field sensors' pull-up bits.
const PORTD: usize = 0x2B;
const PORTF: usize = 0x31;
/// How long after a sensor pin becomes an input its pull-up must be off, cycles.
const PULLUP_CHECK_CYCLES: u64 = 32;
/// TCNT3L (then TCNT3H) in data memory: simavr writes the count there at
/// each read (a cache of the last read; the timer's state is the cycle
/// counter).
const TCNT3_AT: usize = 0x94;
/// Ticks before the earliest end of the wait's USB loop that a skip stops
/// at (see [`Zumo::skip_waits`]).
const SKIP_MARGIN_TICKS: u64 = 8;
/// Instructions one iteration of an idle loop may take.
const LOOP_MAX_INSTRUCTIONS: u32 = 4096;
/// Tries to find an idle loop in one period's wait.
const SKIP_TRIES: u32 = 256;

/// Pixy (CMUcam5) protocol words (`../shared/docs/hardware.md` section 5):
/// a normal block's sync, a colour-code block's sync, a sync read one
/// byte off.
pub const PIXY_SYNC: u16 = 0xAA55;
/// See [`PIXY_SYNC`].
pub const PIXY_SYNC_CC: u16 = 0xAA56;
/// See [`PIXY_SYNC`].
pub const PIXY_SYNC_SWAPPED: u16 = 0x55AA;

/// A puck (signature 1) near, in the left half of the image: the left
/// puck sensor's bit.
pub const PUCK_LEFT: PixyBlock = PixyBlock {
    signature: 1,
    x: 60,
    y: 150,
    width: 20,
    height: 14,
    angle: 0,
};

/// One camera frame as the Pixy sends it, written here from the protocol
/// (not with the firmware's encoder): an extra sync starts the frame, then
/// each block: its sync, the checksum (wrapping sum of the data words),
/// signature, x, y, width, height and, for a colour code (signature above
/// 7, octal digits), the angle.
pub fn pixy_frame_words(blocks: &[PixyBlock]) -> Vec<u16> {
    let mut words = Vec::new();
    if blocks.is_empty() {
        return words;
    }
    words.push(PIXY_SYNC);
    for b in blocks {
        let colour_code = b.signature > 7;
        let mut data = vec![b.signature, b.x, b.y, b.width, b.height];
        if colour_code {
            data.push(b.angle as u16);
        }
        words.push(if colour_code { PIXY_SYNC_CC } else { PIXY_SYNC });
        words.push(data.iter().fold(0u16, |sum, w| sum.wrapping_add(*w)));
        words.extend(data);
    }
    words
}

/// Words as the Pixy sends them on I2C: little-endian.
pub fn pixy_bytes(words: &[u16]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The release ELF `scripts/build-firmware` writes; panics with what to run
/// if it is missing (the tests never skip silently).
pub fn firmware_elf() -> PathBuf {
    firmware_elf_in("firmware", "scripts/build-firmware")
}

/// The ELF a build wrote to `target/avr-none/<dir>/firmware.elf`; panics
/// saying to run `build` (the command that writes it) if it is missing or
/// stale (built from other sources, `crate::figures::check_sources`).
pub fn firmware_elf_in(dir: &str, build: &str) -> PathBuf {
    let elf = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../target/avr-none")
        .join(dir)
        .join("firmware.elf");
    assert!(
        elf.exists(),
        "the firmware ELF {} is missing: run `{build}` (needs gcc-avr, avr-libc and the rust-src \
         component; `scripts/setup` installs them), or run everything with `./scripts/test`",
        elf.display()
    );
    if let Err(e) = crate::figures::check_sources(&elf, build) {
        panic!("{e:#}");
    }
    elf
}

const fn ioctl(a: u8, b: u8, c: u8, d: u8) -> u32 {
    u32::from_be_bytes([a, b, c, d])
}

thread_local! {
    static LAST_AVR: Cell<*mut ffi::avr_t> = const { Cell::new(null_mut()) };
}

unsafe extern "C" fn capture_handle(
    avr: *mut ffi::avr_t,
    _: c_int,
    _: *const c_char,
    _: *mut ffi::__va_list_tag,
) {
    if !avr.is_null() {
        LAST_AVR.with(|c| c.set(avr));
    }
}

/// Loads the ELF and returns simavr's handle of the new core.
fn load(elf: &Path) -> (AvrTester, *mut ffi::avr_t) {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        // avr-tester installs its (silent) logger once, at its first load;
        // ours replaces it afterwards and is never replaced again.
        drop(AvrTester::atmega32u4().with_clock_of_16_mhz().load(elf));
        // SAFETY: `capture_handle` only stores the handle it is given.
        unsafe { ffi::avr_global_logger_set(Some(capture_handle)) };
    });
    LAST_AVR.with(|c| c.set(null_mut()));
    let tester = AvrTester::atmega32u4().with_clock_of_16_mhz().load(elf);
    let avr = LAST_AVR.with(|c| c.get());
    assert!(
        !avr.is_null(),
        "simavr did not pass its handle to the logger"
    );
    (tester, avr)
}

/// One emulated field sensor: its pin's IRQ (the cycle timers' parameter).
struct RcSensor {
    irq: *mut ffi::avr_irq_t,
    /// Its pin's bit in its port's PORT register, in data memory.
    port: usize,
    mask: u8,
    /// Times the pull-up was found on while the sensor discharged.
    pullup_on: Rc<Cell<u32>>,
}

impl RcSensor {
    /// Counts a pull-up left on (the real sensor would not discharge).
    ///
    /// # Safety
    /// `avr` must be the live core.
    unsafe fn check_pullup(&self, avr: *mut ffi::avr_t) -> bool {
        // SAFETY: the caller's contract; `port` lies in the data space.
        let on = unsafe { *(*avr).data.add(self.port) } & self.mask != 0;
        if on {
            self.pullup_on.set(self.pullup_on.get() + 1);
        }
        on
    }
}

/// One emulated wheel encoder: its XOR and B pins and its quadrature phase.
struct Encoder {
    avr: *mut ffi::avr_t,
    pins: *mut ExternalPins,
    xor: Pin,
    b: Pin,
    /// Phase 0..4 in the forward order A B = 00, 10, 11, 01: the XOR pin is
    /// its low bit, B its high bit.
    phase: u8,
    /// Cycles between edges and their direction (`None`: standing).
    every: Option<(u64, bool)>,
    /// Edges sent, forward minus backward.
    steps: i64,
}

impl Encoder {
    /// Sets the pins to the current phase: B first, so that the XOR pin's
    /// edge (the interrupt) sees both new levels.
    ///
    /// # Safety
    /// The core must be live, `pins` the `Zumo`'s, with no other reference to it live.
    unsafe fn drive(&self) {
        // SAFETY: the caller's contract.
        unsafe {
            let pins = &mut *self.pins;
            pins.drive(self.b, self.phase & 2 != 0);
            pins.drive(self.xor, self.phase & 1 != 0);
        }
    }
}

unsafe extern "C" fn on_encoder_edge(
    _: *mut ffi::avr_t,
    when: ffi::avr_cycle_count_t,
    param: *mut c_void,
) -> u64 {
    // SAFETY: `param` is a boxed `Encoder` of the `Zumo`, which outlives the core's timers.
    let e = unsafe { &mut *(param as *mut Encoder) };
    let Some((every, forward)) = e.every else {
        return 0;
    };
    e.phase = if forward {
        (e.phase + 1) % 4
    } else {
        (e.phase + 3) % 4
    };
    e.steps += if forward { 1 } else { -1 };
    // SAFETY: the core is live while it runs its timers.
    unsafe { e.drive() };
    when + every
}

unsafe extern "C" fn on_pullup_check(
    avr: *mut ffi::avr_t,
    _: ffi::avr_cycle_count_t,
    param: *mut c_void,
) -> u64 {
    // SAFETY: as in `on_discharged`.
    let sensor = unsafe { &*(param as *const RcSensor) };
    // SAFETY: simavr passes its live core.
    unsafe { sensor.check_pullup(avr) };
    0
}

/// The I2C lines: pulled up by the board, SDA possibly held low by a
/// device until it has seen some SCL clocks.
struct I2cLines {
    pins: *mut ExternalPins,
    scl: *mut ffi::avr_irq_t,
    /// SDA is held low until this many more falling SCL edges (`Some(u32::MAX)`: for ever).
    sda_held_for: Option<u32>,
    last_scl: u32,
    /// Falling SCL edges seen while SDA was held.
    clocks_while_held: u32,
}

impl I2cLines {
    /// Drives SDA: low while held, else the pull-up's high.
    ///
    /// # Safety
    /// As [`Encoder::drive`].
    unsafe fn apply(&mut self) {
        // SAFETY: the caller's contract.
        unsafe { (*self.pins).drive(pins::I2C_SDA, self.sda_held_for.is_none()) };
    }
}

unsafe extern "C" fn on_scl(_: *mut ffi::avr_irq_t, value: u32, param: *mut c_void) {
    // SAFETY: `param` is the boxed `I2cLines` of the `Zumo`, which outlives the core.
    let lines = unsafe { &mut *(param as *mut I2cLines) };
    let falling = lines.last_scl != 0 && value == 0;
    lines.last_scl = value;
    if let (true, Some(n)) = (falling, lines.sda_held_for) {
        lines.clocks_while_held += 1;
        lines.sda_held_for = match n {
            u32::MAX => Some(n),
            0 | 1 => None,
            n => Some(n - 1),
        };
        if lines.sda_held_for.is_none() {
            // SAFETY: the core is live while it notifies.
            unsafe { lines.apply() };
        }
    }
}

/// Pins driven from outside the chip (buttons with their pull-ups, encoder
/// outputs, the I2C lines' pull-ups and a device on them): simavr's
/// "external" state of each port, so that its emulation of the internal
/// pull-ups (which raises an input whose PORT bit is set whenever the
/// firmware writes PORT) never overrides what drives the pin.
struct ExternalPins {
    avr: *mut ffi::avr_t,
    /// Per port (B, C, D, E, F): the pins driven from outside, and their levels.
    ports: [(u8, u8); 5],
}

impl ExternalPins {
    /// Drives `pin` to `high` from outside.
    ///
    /// # Safety
    /// The core must be live.
    unsafe fn drive(&mut self, pin: Pin, high: bool) {
        let index = match pin.port {
            Port::B => 0,
            Port::C => 1,
            Port::D => 2,
            Port::E => 3,
            Port::F => 4,
        };
        let (mask, value) = &mut self.ports[index];
        *mask |= pin.mask();
        *value = if high {
            *value | pin.mask()
        } else {
            *value & !pin.mask()
        };
        // SAFETY: the caller's contract.
        unsafe {
            set_external(self.avr, pin.port, *mask, *value);
            let irq = ffi::avr_io_getirq(
                self.avr,
                ioctl(b'i', b'o', b'g', pin.port.letter()),
                c_int::from(pin.bit),
            );
            ffi::avr_raise_irq(irq, u32::from(high));
        }
    }
}

/// Sets a port's external state (pins not driven by the firmware read
/// `value` where `mask` is set).
///
/// # Safety
/// `avr` must be the live core.
unsafe fn set_external(avr: *mut ffi::avr_t, port: Port, mask: u8, value: u8) {
    let mut ext = ffi::avr_ioport_external_t {
        _bitfield_align_1: [],
        _bitfield_1: Default::default(),
        __bindgen_padding_0: Default::default(),
    };
    ext.set_name(u64::from(port.letter()));
    ext.set_mask(u64::from(mask));
    ext.set_value(u64::from(value));
    // SAFETY: the caller's contract; `ext` is the ioport's external-state record.
    unsafe {
        ffi::avr_ioctl(
            avr,
            ioctl(b'i', b'o', b'p', port.letter()),
            &mut ext as *mut _ as *mut c_void,
        )
    };
}

/// The emulated Pixy: a byte queue refilled with the current scene once per
/// camera frame (20 ms), and at the first read after the scene changed;
/// zeros when it has nothing; NACK when absent. A frame starts only with
/// the first byte of a read transaction (a word), never between a word's
/// two bytes.
struct Pixy {
    avr: *mut ffi::avr_t,
    present: bool,
    /// The bytes of one frame of the current scene.
    scene: Vec<u8>,
    /// The scene changed since the last frame was queued.
    changed: bool,
    /// The next byte is the first of a read transaction.
    word_start: bool,
    bytes: VecDeque<u8>,
    last_frame: u64,
}

impl Pixy {
    fn next_byte(&mut self) -> u8 {
        // SAFETY: the core outlives the Pixy it serves (field order of `Zumo`).
        let now = unsafe { (*self.avr).cycle };
        let word_start = std::mem::replace(&mut self.word_start, false);
        let due = self.changed || now.saturating_sub(self.last_frame) >= CLOCK_HZ / 50;
        if self.bytes.is_empty() && word_start && due {
            self.changed = false;
            self.last_frame = now;
            self.bytes.extend(&self.scene);
        }
        self.bytes.pop_front().unwrap_or(0)
    }

    fn on_packet(&mut self, p: TwiPacket) -> Option<TwiPacket> {
        if !self.present || p.addr >> 1 != PIXY_ADDRESS {
            return None;
        }
        if p.is_start() {
            self.word_start = true;
            return Some(p.respond_ack());
        }
        if p.is_read() {
            return Some(p.respond_data(self.next_byte()));
        }
        None
    }
}

/// What the simavr callbacks record and read.
struct State {
    avr: *mut ffi::avr_t,
    uart: Vec<u8>,
    marks: Vec<(u8, u64)>,
    /// The last marker written.
    last_mark: u8,
    /// The cycle of the last period-start marker (4).
    period_start: Option<u64>,
    /// Decision-end markers seen.
    decisions: u64,
    /// The bootloader key (SRAM 0x0800) at each start-up that followed a
    /// watchdog reset (MCUSR.WDRF set when the firmware clears MCUSR).
    watchdog_resets: Vec<u16>,
    ddr: [u8; 2],
    /// Discharge delay of each sensor in cycles; `None` = never (timeout).
    delays: [Option<u64>; 3],
    sensors: [RcSensor; 3],
}

unsafe extern "C" fn on_uart(_: *mut ffi::avr_irq_t, value: u32, param: *mut c_void) {
    // SAFETY: `param` is the boxed `State` registered with this callback,
    // which outlives the simulator (field order of `Zumo`); simavr calls
    // back on this thread only, while no other reference to it is live.
    let state = unsafe { &mut *(param as *mut State) };
    state.uart.push(value as u8);
}

unsafe extern "C" fn on_gpior0(
    avr: *mut ffi::avr_t,
    addr: ffi::avr_io_addr_t,
    v: u8,
    param: *mut c_void,
) {
    // SAFETY: simavr passes its live core and an address inside its data
    // space; `param` is the boxed `State`, as in `on_uart`.
    unsafe {
        *(*avr).data.add(usize::from(addr)) = v;
        let state = &mut *(param as *mut State);
        state.marks.push((v, (*avr).cycle));
        state.last_mark = v;
        if v == 4 {
            state.period_start = Some((*avr).cycle);
        }
        state.decisions += u64::from(v == 2);
    }
}

/// MCUSR written (the firmware clears it first thing): after a watchdog
/// reset (WDRF, bit 3) the key at 0x0800 is what the bootloader would see.
unsafe extern "C" fn on_mcusr(
    avr: *mut ffi::avr_t,
    addr: ffi::avr_io_addr_t,
    v: u8,
    param: *mut c_void,
) {
    // SAFETY: as in `on_gpior0`.
    unsafe {
        let reg = (*avr).data.add(usize::from(addr));
        if *reg & 1 << 3 != 0 {
            let key = u16::from_le_bytes([*(*avr).data.add(0x0800), *(*avr).data.add(0x0801)]);
            (*(param as *mut State)).watchdog_resets.push(key);
        }
        *reg = v;
    }
}

unsafe extern "C" fn on_discharged(
    avr: *mut ffi::avr_t,
    _: ffi::avr_cycle_count_t,
    param: *mut c_void,
) -> u64 {
    // SAFETY: `param` points into the boxed `State`'s sensors (registered in
    // `on_ddr`); its IRQ is the pin's, valid while the core lives.
    let sensor = unsafe { &*(param as *const RcSensor) };
    // A pull-up left on holds the pin high: it never discharges.
    // SAFETY: simavr passes its live core.
    if unsafe { !sensor.check_pullup(avr) } {
        unsafe { ffi::avr_raise_irq(sensor.irq, 0) };
    }
    0
}

/// A direction register of `port` changed to `value`: a field sensor
/// pin that became an input starts discharging, one that became an output
/// stops.
///
/// # Safety
/// `param` must be the boxed `State` of a live core, with no other
/// reference to it live.
unsafe fn on_ddr(port: Port, value: u32, param: *mut c_void) {
    // SAFETY: the caller's contract.
    let state = unsafe { &mut *(param as *mut State) };
    let slot = usize::from(port == Port::D);
    let (old, new) = (state.ddr[slot], value as u8);
    state.ddr[slot] = new;
    for (i, pin) in pins::FIELD_SENSORS.iter().enumerate() {
        let sensor = &mut state.sensors[i] as *mut RcSensor;
        if pin.port != port {
            continue;
        }
        let mask = pin.mask();
        if old & mask != 0 && new & mask == 0 {
            // Charged, now an input: discharge after the sensor's delay.
            // SAFETY: the core is live; the sensor lives in the boxed
            // state, which outlives every timer of the core.
            unsafe {
                ffi::avr_cycle_timer_register(
                    state.avr,
                    PULLUP_CHECK_CYCLES,
                    Some(on_pullup_check),
                    sensor as *mut c_void,
                );
                if let Some(delay) = state.delays[i] {
                    ffi::avr_cycle_timer_register(
                        state.avr,
                        delay,
                        Some(on_discharged),
                        sensor as *mut c_void,
                    );
                }
            }
        } else if old & mask == 0 && new & mask != 0 {
            // SAFETY: as above; cancelling an unregistered timer is a no-op.
            unsafe {
                ffi::avr_cycle_timer_cancel(state.avr, Some(on_discharged), sensor as *mut c_void);
                ffi::avr_cycle_timer_cancel(
                    state.avr,
                    Some(on_pullup_check),
                    sensor as *mut c_void,
                );
            }
        }
    }
}

unsafe extern "C" fn on_ddr_f(_: *mut ffi::avr_irq_t, value: u32, param: *mut c_void) {
    // SAFETY: registered with the boxed `State` as its parameter.
    unsafe { on_ddr(Port::F, value, param) }
}

unsafe extern "C" fn on_ddr_d(_: *mut ffi::avr_irq_t, value: u32, param: *mut c_void) {
    // SAFETY: registered with the boxed `State` as its parameter.
    unsafe { on_ddr(Port::D, value, param) }
}

#[repr(C)]
struct EepromDesc {
    ee: *mut u8,
    offset: u16,
    size: u32,
}

/// The firmware running in simavr on an emulated Zumo.
pub struct Zumo {
    // Field order is drop order: the simulator goes before the state its
    // callbacks point to.
    tester: AvrTester,
    state: Box<State>,
    pixy: Rc<RefCell<Pixy>>,
    encoders: [Box<Encoder>; 2],
    i2c: Box<I2cLines>,
    external: Box<ExternalPins>,
    decoded: usize,
    pullup_on: Rc<Cell<u32>>,
    /// What simavr's callbacks registered by other modules point to
    /// (`usb_host`'s background host), dropped after the core.
    kept: Vec<Box<dyn std::any::Any>>,
    /// Whether [`Zumo::run_to_decision`] fast-forwards the period's wait.
    skip_waits: bool,
    /// The period (its start marker's cycle) whose wait was skipped or
    /// given up on.
    skipped_period: Option<u64>,
    /// Cycles fast-forwarded.
    cycles_skipped: u64,
    /// The data space at the start of a candidate idle loop's iteration.
    snapshot: Vec<u8>,
}

impl Zumo {
    /// Loads the release ELF (erased EEPROM, Pixy present seeing nothing,
    /// sensors discharging after 1 ms) and runs its start-up.
    pub fn boot() -> Zumo {
        Zumo::boot_elf(&firmware_elf())
    }

    /// [`Zumo::boot`] with another build of the firmware.
    pub fn boot_elf(elf: &Path) -> Zumo {
        let (tester, avr) = load(elf);
        let pullup_on = Rc::new(Cell::new(0));
        let pin_irq = |pin: Pin| {
            // SAFETY: `avr` is the core just loaded; null IRQs are checked below.
            unsafe {
                ffi::avr_io_getirq(
                    avr,
                    ioctl(b'i', b'o', b'g', pin.port.letter()),
                    c_int::from(pin.bit),
                )
            }
        };
        let mut state = Box::new(State {
            avr,
            uart: Vec::new(),
            marks: Vec::new(),
            last_mark: 0,
            period_start: None,
            decisions: 0,
            watchdog_resets: Vec::new(),
            ddr: [0; 2],
            delays: [Some(CLOCK_HZ / 1000); 3],
            sensors: pins::FIELD_SENSORS.map(|pin| RcSensor {
                irq: pin_irq(pin),
                port: if pin.port == Port::F { PORTF } else { PORTD },
                mask: pin.mask(),
                pullup_on: pullup_on.clone(),
            }),
        });
        let mut external = Box::new(ExternalPins {
            avr,
            ports: [(0, 0); 5],
        });
        let external_ptr = &mut *external as *mut ExternalPins;
        let encoder = |xor: Pin, b: Pin| {
            Box::new(Encoder {
                avr,
                pins: external_ptr,
                xor,
                b,
                phase: 0,
                every: None,
                steps: 0,
            })
        };
        let encoders = [
            encoder(pins::ENCODER_LEFT_XOR, pins::ENCODER_LEFT_B),
            encoder(pins::ENCODER_RIGHT_XOR, pins::ENCODER_RIGHT_B),
        ];
        let mut i2c = Box::new(I2cLines {
            pins: external_ptr,
            scl: pin_irq(pins::I2C_SCL),
            sda_held_for: None,
            last_scl: 1,
            clocks_while_held: 0,
        });
        let state_ptr = &mut *state as *mut State;
        // SAFETY: `avr` is the live core; the callbacks get the boxed state,
        // which `Zumo` drops after the simulator (field order).
        unsafe {
            assert!(
                state.sensors.iter().all(|s| !s.irq.is_null()),
                "no field sensor pins"
            );
            // USART1: bytes out, not to stdout.
            let mut flags: u32 = 0;
            ffi::avr_ioctl(
                avr,
                ioctl(b'u', b'a', b'g', b'1'),
                &mut flags as *mut u32 as *mut c_void,
            );
            flags &= !ffi::AVR_UART_FLAG_STDIO;
            ffi::avr_ioctl(
                avr,
                ioctl(b'u', b'a', b's', b'1'),
                &mut flags as *mut u32 as *mut c_void,
            );
            let uart = ffi::avr_io_getirq(
                avr,
                ioctl(b'u', b'a', b'r', b'1'),
                ffi::UART_IRQ_OUTPUT as c_int,
            );
            ffi::avr_irq_register_notify(uart, Some(on_uart), state_ptr as *mut c_void);
            for (port, f) in [
                (Port::F, on_ddr_f as unsafe extern "C" fn(_, _, _)),
                (Port::D, on_ddr_d),
            ] {
                let irq = ffi::avr_io_getirq(
                    avr,
                    ioctl(b'i', b'o', b'g', port.letter()),
                    ffi::IOPORT_IRQ_DIRECTION_ALL as c_int,
                );
                ffi::avr_irq_register_notify(irq, Some(f), state_ptr as *mut c_void);
            }
            ffi::avr_register_io_write(avr, GPIOR0, Some(on_gpior0), state_ptr as *mut c_void);
            ffi::avr_register_io_write(avr, MCUSR, Some(on_mcusr), state_ptr as *mut c_void);
            for e in &encoders {
                e.drive();
            }
            let lines = &mut *i2c as *mut I2cLines;
            ffi::avr_irq_register_notify(i2c.scl, Some(on_scl), lines as *mut c_void);
            (*external_ptr).drive(pins::I2C_SCL, true);
            i2c.apply();
        }
        let pixy = Rc::new(RefCell::new(Pixy {
            avr,
            present: true,
            scene: Vec::new(),
            changed: false,
            word_start: false,
            bytes: VecDeque::new(),
            last_frame: 0,
        }));
        let mut zumo = Zumo {
            tester,
            state,
            pixy: pixy.clone(),
            encoders,
            i2c,
            external,
            decoded: 0,
            pullup_on,
            kept: Vec::new(),
            skip_waits: false,
            skipped_period: None,
            cycles_skipped: 0,
            snapshot: Vec::new(),
        };
        zumo.tester
            .twi0()
            .attach_slave_fn(move |p| pixy.borrow_mut().on_packet(p));
        zumo.set_button(pins::BUTTON_A, false);
        zumo.set_button(pins::BUTTON_B_LED_GREEN, false);
        zumo
    }

    /// Stores bytes in the simulated EEPROM.
    pub fn write_eeprom(&mut self, offset: u16, bytes: &[u8]) {
        let mut copy = bytes.to_vec();
        let mut desc = EepromDesc {
            ee: copy.as_mut_ptr(),
            offset,
            size: copy.len() as u32,
        };
        // SAFETY: simavr copies `size` bytes from `ee`, which holds them.
        let r = unsafe {
            ffi::avr_ioctl(
                self.state.avr,
                ioctl(b'e', b'e', b's', b'p'),
                &mut desc as *mut _ as *mut c_void,
            )
        };
        assert_eq!(r, 0, "EEPROM write refused");
    }

    /// Writes `robot_id` into the image's identity record in simulated
    /// flash (`shared::FirmwareIdentity`, the only place the firmware reads
    /// its id from): the image then runs as a build with
    /// `FIRMWARE_ROBOT_ID=robot_id` does (its USB serial number aside), so
    /// one ELF serves every robot of a swarm. Call it before the firmware
    /// runs. Fails unless the image holds exactly one record.
    pub fn set_robot_id(&mut self, robot_id: u8) -> anyhow::Result<()> {
        let avr = self.state.avr;
        // SAFETY: the core is live; `flash` holds `flashend + 1` bytes.
        let flash =
            unsafe { std::slice::from_raw_parts_mut((*avr).flash, (*avr).flashend as usize + 1) };
        let len = shared::FirmwareIdentity::LEN;
        let found: Vec<usize> = (0..=flash.len() - len)
            .filter(|&i| {
                let w = &flash[i..i + len];
                shared::FirmwareIdentity::find_all(w).next().is_some()
            })
            .collect();
        let [at] = found[..] else {
            anyhow::bail!(
                "the firmware image holds {} identity records, not one",
                found.len()
            );
        };
        flash[at + shared::FirmwareIdentity::ROBOT_ID_OFFSET] = robot_id;
        Ok(())
    }

    /// Reads bytes of the simulated EEPROM.
    pub fn read_eeprom(&mut self, offset: u16, len: usize) -> Vec<u8> {
        let mut desc = EepromDesc {
            ee: null_mut(),
            offset,
            size: len as u32,
        };
        // SAFETY: simavr points `ee` at its EEPROM at `offset`.
        let r = unsafe {
            ffi::avr_ioctl(
                self.state.avr,
                ioctl(b'e', b'e', b'g', b'p'),
                &mut desc as *mut _ as *mut c_void,
            )
        };
        assert_eq!(r, 0, "EEPROM read refused");
        // SAFETY: the read succeeded, so `ee` points at `len` bytes of the
        // core's EEPROM (offset + len within it, or simavr refuses).
        unsafe { std::slice::from_raw_parts(desc.ee, len).to_vec() }
    }

    /// Sets the field sensors' discharge times in Timer3 ticks (`None`: the
    /// sensor never discharges and times out).
    pub fn set_sensor_ticks(&mut self, ticks: [Option<u16>; 3]) {
        self.set_sensor_cycles(ticks.map(|t| t.map(|t| u64::from(t) * CYCLES_PER_TICK)));
    }

    /// Sets the field sensors' discharge delays in CPU cycles after each
    /// pin becomes an input (`None`: never discharges). Takes effect at
    /// the next measurement.
    pub fn set_sensor_cycles(&mut self, cycles: [Option<u64>; 3]) {
        self.state.delays = cycles;
    }

    /// What the Pixy sees from now on: its next frame (served at the next
    /// read) shows it.
    pub fn show(&mut self, blocks: &[PixyBlock]) {
        self.show_bytes(&pixy_bytes(&pixy_frame_words(blocks)));
    }

    /// What the Pixy sends per frame from now on, byte for byte (garbage,
    /// misaligned words, bad checksums: anything).
    pub fn show_bytes(&mut self, bytes: &[u8]) {
        let mut p = self.pixy.borrow_mut();
        p.scene = bytes.to_vec();
        p.bytes.clear();
        p.changed = true;
    }

    /// Drives the wheels: each encoder sends `counts_per_second` edges
    /// (negative: backwards; 0: stands), evenly spaced, from now on.
    pub fn set_wheel_counts_per_second(&mut self, counts_per_second: [i32; 2]) {
        for (e, rate) in self.encoders.iter_mut().zip(counts_per_second) {
            let param = &mut **e as *mut Encoder as *mut c_void;
            // SAFETY: the core is live; the encoder is boxed in `self`, which outlives the core's timers.
            unsafe { ffi::avr_cycle_timer_cancel(e.avr, Some(on_encoder_edge), param) };
            e.every = (rate != 0).then(|| (CLOCK_HZ / u64::from(rate.unsigned_abs()), rate > 0));
            if let Some((every, _)) = e.every {
                // SAFETY: as above.
                unsafe {
                    ffi::avr_cycle_timer_register(e.avr, every, Some(on_encoder_edge), param)
                };
            }
        }
    }

    /// Encoder edges sent since boot, left and right (forward minus backward).
    pub fn encoder_steps(&self) -> [i64; 2] {
        [self.encoders[0].steps, self.encoders[1].steps]
    }

    /// A device on the I2C bus holds SDA low until it has seen `clocks`
    /// falling SCL edges (`None`: for ever), as a slave cut off mid-byte does.
    pub fn hold_sda_low(&mut self, clocks: Option<u32>) {
        self.i2c.sda_held_for = Some(clocks.unwrap_or(u32::MAX).max(1));
        self.i2c.clocks_while_held = 0;
        // SAFETY: the core is live.
        unsafe { self.i2c.apply() };
    }

    /// Falling SCL edges the firmware clocked while SDA was held low.
    pub fn scl_clocks_while_sda_held(&self) -> u32 {
        self.i2c.clocks_while_held
    }

    /// Whether SDA is still held low.
    pub fn sda_held(&self) -> bool {
        self.i2c.sda_held_for.is_some()
    }

    /// Connects or disconnects the Pixy (disconnected: it NACKs its address).
    pub fn connect_pixy(&mut self, present: bool) {
        let mut p = self.pixy.borrow_mut();
        p.present = present;
        p.bytes.clear();
    }

    fn set_button(&mut self, pin: Pin, pressed: bool) {
        // Released, the pull-up makes it read high.
        // SAFETY: the core is live; no callback holds the external pins now.
        unsafe { self.external.drive(pin, !pressed) };
    }

    /// Presses button A for 60 ms (three control periods), then releases it.
    pub fn press_a(&mut self) {
        self.set_button(pins::BUTTON_A, true);
        self.run_ms(60);
        self.set_button(pins::BUTTON_A, false);
    }

    /// Presses button B for 60 ms, then releases it.
    pub fn press_b(&mut self) {
        self.set_button(pins::BUTTON_B_LED_GREEN, true);
        self.run_ms(60);
        self.set_button(pins::BUTTON_B_LED_GREEN, false);
    }

    /// The calibration procedure (`docs/firmware.md`): button B, then the
    /// display's white screen for 300 ms and its black screen for 300 ms,
    /// as RC delays in CPU cycles on the sensor pins (`None`: never
    /// discharges).
    pub fn calibrate_cycles(&mut self, white: [Option<u64>; 3], black: [Option<u64>; 3]) {
        self.press_b();
        self.set_sensor_cycles(white);
        self.run_ms(300);
        self.set_sensor_cycles(black);
        self.run_ms(300);
    }

    /// [`Zumo::calibrate_cycles`] with the times in Timer3 ticks.
    pub fn calibrate_ticks(&mut self, white: [Option<u16>; 3], black: [Option<u16>; 3]) {
        let cycles = |t: [Option<u16>; 3]| t.map(|t| t.map(|t| u64::from(t) * CYCLES_PER_TICK));
        self.calibrate_cycles(cycles(white), cycles(black));
    }

    /// The procedure with a white screen of 100, 110, 120 ticks and a black
    /// one of 400, 410, 420 ticks.
    pub fn calibrate(&mut self) {
        self.calibrate_ticks(
            [Some(100), Some(110), Some(120)],
            [Some(400), Some(410), Some(420)],
        );
    }

    /// Runs the firmware for `ms` simulated milliseconds.
    pub fn run_ms(&mut self, ms: u64) {
        self.tester.run_for_ms(ms);
    }

    /// Runs until the firmware ends its next decision (right after the
    /// motor writes, before the period's log frame); returns the number of
    /// decisions so far, which is the tick of that period's log frame.
    /// Panics if no decision comes within 100 ms.
    pub fn run_to_decision(&mut self) -> u64 {
        let before = self.state.decisions;
        // SAFETY: the core is live while `self` is.
        let deadline = unsafe { (*self.state.avr).cycle } + CLOCK_HZ / 10;
        while self.state.decisions == before {
            if self.skip_waits
                && self.state.last_mark == 3
                && self.skipped_period != self.state.period_start
            {
                self.skip_wait();
            }
            self.step();
            // SAFETY: as above.
            assert!(
                unsafe { (*self.state.avr).cycle } < deadline,
                "no decision within 100 ms"
            );
        }
        self.state.decisions
    }

    /// Runs one instruction, then the cycle timers and interrupts due, with
    /// simavr's own stepping: what `AvrTester::run` does, without its
    /// per-instruction bookkeeping (UART flushes and async components,
    /// none of which a `Zumo` uses). Panics if the core stops running
    /// (crashed, or asleep: nothing here wakes it).
    fn step(&mut self) {
        let avr = self.state.avr;
        // SAFETY: the core is live; simavr steps it on this thread.
        let state = unsafe {
            ffi::avr_run(avr);
            (*avr).state
        };
        assert!(
            state == ffi::cpu_Running as c_int,
            "the AVR stopped running (simavr state {state}: crashed or asleep)"
        );
    }

    /// Makes [`Zumo::run_to_decision`] fast-forward the firmware's busy
    /// wait for the next period instead of simulating it cycle by cycle,
    /// without changing what the firmware computes. After a period's log
    /// frame (marker 3), it looks for an idle loop: from some instruction,
    /// one pass that comes back to it with the data space (registers, I/O,
    /// SRAM) and the status flags as they were, but for the Timer3 count
    /// simavr caches at each read. Each further pass would then do the
    /// same as long as the count it reads does not end the wait and no
    /// simavr cycle timer (the peripherals, the emulated sensors) fires
    /// and no interrupt is pending; so the cycle counter is advanced by
    /// whole passes, up to the earlier of the next cycle timer and
    /// [`SKIP_MARGIN_TICKS`] before the earliest tick at which the wait's
    /// USB loop can end (its period started at most two ticks before its
    /// start marker, and the loop ends [`USB_QUIET_TICKS`] before the
    /// period's [`PERIOD_TICKS`]). The rest of the wait runs as before.
    pub fn skip_waits(&mut self, on: bool) {
        self.skip_waits = on;
    }

    /// CPU cycles fast-forwarded by [`Zumo::skip_waits`] since boot.
    pub fn cycles_skipped(&self) -> u64 {
        self.cycles_skipped
    }

    /// The data space, compared for an idle loop's pass (the Timer3 count
    /// cache aside).
    fn data_space(&self) -> &[u8] {
        // SAFETY: the core is live; its data space holds `RAM_END` bytes.
        unsafe { std::slice::from_raw_parts((*self.state.avr).data, RAM_END) }
    }

    /// One fast-forward of the current period's wait (see [`Zumo::skip_waits`]).
    fn skip_wait(&mut self) {
        let avr = self.state.avr;
        let period = self.state.period_start;
        let Some(start) = period else {
            self.skipped_period = period;
            return;
        };
        let ticks = u64::from(PERIOD_TICKS - USB_QUIET_TICKS) - 2 - SKIP_MARGIN_TICKS;
        let end = start + ticks * CYCLES_PER_TICK;
        for _ in 0..SKIP_TRIES {
            // SAFETY (this block's reads of the core): the core is live.
            let (pc, sreg, from) = unsafe { ((*avr).pc, (*avr).sreg, (*avr).cycle) };
            let mut snapshot = std::mem::take(&mut self.snapshot);
            snapshot.clear();
            snapshot.extend_from_slice(self.data_space());
            let mut n = 0;
            loop {
                self.step();
                n += 1;
                // SAFETY: as above.
                let back = unsafe { (*avr).pc } == pc;
                if back || n == LOOP_MAX_INSTRUCTIONS || self.state.last_mark != 3 {
                    break;
                }
            }
            // SAFETY: as above.
            let (now, same_flags, back) =
                unsafe { ((*avr).cycle, (*avr).sreg == sreg, (*avr).pc == pc) };
            let data = self.data_space();
            let (low, high) = (TCNT3_AT, TCNT3_AT + 2);
            let idle = back
                && same_flags
                && data[..low] == snapshot[..low]
                && data[high..] == snapshot[high..];
            self.snapshot = snapshot;
            if self.state.last_mark != 3 {
                break;
            }
            if !idle {
                // Another instruction to start from: a register holding a
                // dead value may differ at this one.
                self.step();
                continue;
            }
            // SAFETY: the core is live; the pool's head is its earliest timer.
            let (next_timer, pending) = unsafe {
                let head = (*avr).cycle_timers.timer;
                let when = if head.is_null() {
                    u64::MAX
                } else {
                    (*head).when
                };
                (when, ffi::avr_has_pending_interrupts(avr) != 0)
            };
            let pass = now - from;
            let limit = end.min(next_timer.saturating_sub(1));
            let passes = if pending {
                0
            } else {
                limit.saturating_sub(now) / pass
            };
            if passes == 0 {
                break;
            }
            // SAFETY: the core is live and between instructions.
            unsafe { (*avr).cycle += passes * pass };
            self.cycles_skipped += passes * pass;
        }
        self.skipped_period = period;
    }

    /// Decisions the firmware has ended since boot (the tick of its last
    /// period's log frame).
    pub fn decisions(&self) -> u64 {
        self.state.decisions
    }

    /// CPU cycles simulated since boot.
    pub fn cycles(&self) -> u64 {
        // SAFETY: the core is live while `self` is.
        unsafe { (*self.state.avr).cycle }
    }

    /// simavr's handle of the running core (for the USB host's ioctls).
    pub(crate) fn core(&self) -> *mut ffi::avr_t {
        self.state.avr
    }

    /// Runs the firmware for `us` simulated microseconds.
    pub fn run_us(&mut self, us: u64) {
        self.tester.run_for_us(us);
    }

    /// Keeps `value` alive as long as the core (a callback's parameter).
    pub(crate) fn keep<T: 'static>(&mut self, value: Box<T>) -> &T {
        self.kept.push(value);
        self.kept
            .last()
            .and_then(|b| b.downcast_ref::<T>())
            .expect("just kept")
    }

    /// A value kept by [`Zumo::keep`], by type.
    pub(crate) fn kept<T: 'static>(&self) -> Option<&T> {
        self.kept.iter().find_map(|b| b.downcast_ref::<T>())
    }

    /// A byte of the core's data space (registers, I/O, SRAM).
    pub(crate) fn data(&self, addr: usize) -> u8 {
        assert!(
            addr < RAM_END,
            "data address {addr:#x} outside the 32U4's data space"
        );
        // SAFETY: the core is live and `addr` lies in its data space.
        unsafe { *(*self.state.avr).data.add(addr) }
    }

    fn word(&self, addr: usize) -> u16 {
        u16::from_le_bytes([self.data(addr), self.data(addr + 1)])
    }

    /// Motor duties as the firmware wrote them: (left = OCR1B, right = OCR1A).
    pub fn duties(&self) -> (u16, u16) {
        (self.word(OCR1B), self.word(OCR1A))
    }

    /// Direction pin levels (left, right); high = reverse.
    pub fn directions(&self) -> (bool, bool) {
        let b = self.data(PORTB);
        (
            b & pins::DIR_LEFT.mask() != 0,
            b & pins::DIR_RIGHT.mask() != 0,
        )
    }

    /// Fills the free SRAM between the statics and the stack pointer with a
    /// pattern, for [`Zumo::stack_low_water`].
    pub fn paint_stack(&mut self) {
        let sp = usize::from(self.word(SP));
        for addr in STATICS_END..sp.min(RAM_END) {
            // SAFETY: the core is live and `addr` lies in its SRAM.
            unsafe { *(*self.state.avr).data.add(addr) = PAINT };
        }
    }

    /// Lowest SRAM address the stack has written since [`Zumo::paint_stack`].
    pub fn stack_low_water(&self) -> usize {
        (STATICS_END..RAM_END)
            .find(|a| self.data(*a) != PAINT)
            .unwrap_or(RAM_END)
    }

    /// The word at SRAM 0x0800 (the bootloader's key).
    pub fn boot_key(&self) -> u16 {
        self.word(0x0800)
    }

    /// The bootloader key found at each watchdog reset so far (0x7777:
    /// the A-Star bootloader would have stayed in itself).
    pub fn watchdog_resets(&self) -> &[u16] {
        &self.state.watchdog_resets
    }

    /// Runs the firmware with simavr's own stepping (avr-tester cannot
    /// step over a reset: simavr restarts its cycle counter) until it
    /// starts again after a watchdog reset, or `max_ms` pass. Returns the
    /// simulated milliseconds until that start, if it came.
    pub fn run_until_watchdog_reset(&mut self, max_ms: u64) -> Option<u64> {
        let avr = self.state.avr;
        let seen = self.state.watchdog_resets.len();
        let mut elapsed = 0u64;
        // SAFETY: the core is live; simavr steps it on this thread.
        let mut last = unsafe { (*avr).cycle };
        while elapsed < max_ms * (CLOCK_HZ / 1000) {
            // SAFETY: as above.
            unsafe { ffi::avr_run(avr) };
            let now = unsafe { (*avr).cycle };
            elapsed += if now >= last { now - last } else { now };
            last = now;
            if self.state.watchdog_resets.len() > seen {
                return Some(elapsed / (CLOCK_HZ / 1000));
            }
        }
        None
    }

    /// Every byte the firmware has sent on USART1 since boot (or since the
    /// last [`Zumo::forget_frames`]): the raw serial stream a host would
    /// receive (for the monitor and replay tests).
    pub fn uart_bytes(&self) -> &[u8] {
        &self.state.uart
    }

    /// Drops the serial bytes [`Zumo::frames`] has decoded, so that a
    /// long run's stream does not grow without end.
    pub fn forget_frames(&mut self) {
        self.state.uart.drain(..self.decoded);
        self.decoded = 0;
    }

    /// The cycle markers (GPIOR0 value, cycle) recorded since boot or the
    /// last call, in order; the span methods ([`Zumo::period_cycles`] and
    /// the others) see only markers recorded after it.
    pub fn take_marks(&mut self) -> Vec<(u8, u64)> {
        std::mem::take(&mut self.state.marks)
    }

    /// Log frames received since the last call, decoded with `shared`.
    /// Panics if the firmware ever left a field sensor's pull-up on while
    /// it discharged.
    pub fn frames(&mut self) -> Vec<Result<LogFrame, LogError>> {
        let pullups = self.pullup_on.get();
        assert_eq!(
            pullups, 0,
            "the firmware left a field sensor's pull-up on while it discharged ({pullups} times)"
        );
        let uart = &self.state.uart;
        let mut out = Vec::new();
        let mut start = self.decoded;
        for (i, b) in uart.iter().enumerate().skip(self.decoded) {
            if *b == LogFrame::DELIMITER {
                out.push(LogFrame::decode(&uart[start..i]));
                start = i + 1;
            }
        }
        self.decoded = start;
        out
    }

    /// Cycles from each decision-start marker to its decision-end marker.
    pub fn decision_cycles(&self) -> Vec<u64> {
        self.marker_spans(1, 2)
    }

    /// Cycles from each period's start (marker 4) to the end of its log
    /// frame (marker 3): the period's work, which must fit in 20 ms.
    pub fn period_work_cycles(&self) -> Vec<u64> {
        self.marker_spans(4, 3)
    }

    /// Cycles from each period's start (marker 4) to its decision (marker
    /// 1): buttons, the field sensors' RC timing and the camera's read.
    pub fn sensing_cycles(&self) -> Vec<u64> {
        self.marker_spans(4, 1)
    }

    /// Cycles from each decision's end (marker 2) to the end of its log
    /// frame (marker 3): EEPROM, LEDs, the frame on USART1 and into USB.
    pub fn logging_cycles(&self) -> Vec<u64> {
        self.marker_spans(2, 3)
    }

    /// Cycles between consecutive period starts.
    pub fn period_cycles(&self) -> Vec<u64> {
        let starts: Vec<u64> = self
            .state
            .marks
            .iter()
            .filter(|m| m.0 == 4)
            .map(|m| m.1)
            .collect();
        starts.windows(2).map(|w| w[1] - w[0]).collect()
    }

    fn marker_spans(&self, from: u8, to: u8) -> Vec<u64> {
        let mut spans = Vec::new();
        let mut start = None;
        for &(v, cycle) in &self.state.marks {
            if v == from {
                start = Some(cycle);
            } else if v == to {
                spans.extend(start.take().map(|s| cycle - s));
            }
        }
        spans
    }
}
