//! The firmware ELF running in simavr, wired like a Zumo 32U4 on a field:
//! RC-timed field sensors, a Pixy on TWI, buttons, motor registers, the
//! USART1 log and the decision marker.
//!
//! `avr-tester` runs the simulation; what it does not offer (USART1 on the
//! 32U4, data memory, the cycle counter, EEPROM, I/O register hooks) goes
//! through simavr's own handle (`simavr-ffi`): simavr passes the new core to
//! the global logger when `avr-tester` loads an ELF, and avr-tester installs
//! its own logger at its first load only, so ours, installed after a first
//! throwaway load, catches every later core's handle (see `load`).

use avr_tester::{AvrTester, TwiPacket};
use firmware::pins::{self, Pin, Port, PIXY_ADDRESS};
use firmware::pixy::encode_frame;
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
/// The stack pointer (SPL, SPH) in data memory.
const SP: usize = 0x5D;
/// Above the firmware's statics at their budget (0x0100 + 1 KiB of .data + .bss).
const STATICS_END: usize = 0x0500;
/// One past the last SRAM byte.
const RAM_END: usize = 0x0B00;
/// The stack paint pattern.
const PAINT: u8 = 0xA5;

/// The release ELF `scripts/build-firmware` writes; panics with what to run
/// if it is missing (the tests never skip silently).
pub fn firmware_elf() -> PathBuf {
    firmware_elf_in("firmware", "scripts/build-firmware")
}

/// The ELF a build wrote to `target/avr-none/<dir>/firmware.elf`; panics
/// saying to run `build` (the command that writes it) if it is missing.
pub fn firmware_elf_in(dir: &str, build: &str) -> PathBuf {
    let elf = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/avr-none").join(dir).join("firmware.elf");
    assert!(
        elf.exists(),
        "the firmware ELF {} is missing: run `{build}` (needs gcc-avr, avr-libc and the rust-src \
         component; `scripts/setup` installs them), or run everything with `./scripts/test`",
        elf.display()
    );
    elf
}

const fn ioctl(a: u8, b: u8, c: u8, d: u8) -> u32 {
    u32::from_be_bytes([a, b, c, d])
}

thread_local! {
    static LAST_AVR: Cell<*mut ffi::avr_t> = const { Cell::new(null_mut()) };
}

unsafe extern "C" fn capture_handle(avr: *mut ffi::avr_t, _: c_int, _: *const c_char, _: *mut ffi::__va_list_tag) {
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
    assert!(!avr.is_null(), "simavr did not pass its handle to the logger");
    (tester, avr)
}

/// One emulated field sensor: its pin's IRQ (the cycle timer's parameter).
struct RcSensor {
    irq: *mut ffi::avr_irq_t,
}

/// The emulated Pixy: a byte queue refilled with the current scene once per
/// camera frame (20 ms), and at the first read after the scene changed;
/// zeros when it has nothing; NACK when absent. A frame starts only with
/// the first byte of a read transaction (a word), never between a word's
/// two bytes.
struct Pixy {
    avr: *mut ffi::avr_t,
    present: bool,
    scene: Vec<PixyBlock>,
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
            let mut words = [0u16; 128];
            let n = encode_frame(&self.scene, &mut words);
            self.bytes.extend(words[..n].iter().flat_map(|w| w.to_le_bytes()));
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
    /// Decision-end markers seen.
    decisions: u64,
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

unsafe extern "C" fn on_gpior0(avr: *mut ffi::avr_t, addr: ffi::avr_io_addr_t, v: u8, param: *mut c_void) {
    // SAFETY: simavr passes its live core and an address inside its data
    // space; `param` is the boxed `State`, as in `on_uart`.
    unsafe {
        *(*avr).data.add(usize::from(addr)) = v;
        let state = &mut *(param as *mut State);
        state.marks.push((v, (*avr).cycle));
        state.decisions += u64::from(v == 2);
    }
}

unsafe extern "C" fn on_discharged(_: *mut ffi::avr_t, _: ffi::avr_cycle_count_t, param: *mut c_void) -> u64 {
    // SAFETY: `param` points into the boxed `State`'s sensors (registered in
    // `on_ddr`); its IRQ is the pin's, valid while the core lives.
    let sensor = unsafe { &*(param as *const RcSensor) };
    unsafe { ffi::avr_raise_irq(sensor.irq, 0) };
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
            if let Some(delay) = state.delays[i] {
                // SAFETY: the core is live; the sensor lives in the boxed
                // state, which outlives every timer of the core.
                unsafe { ffi::avr_cycle_timer_register(state.avr, delay, Some(on_discharged), sensor as *mut c_void) };
            }
        } else if old & mask == 0 && new & mask != 0 {
            // SAFETY: as above; cancelling an unregistered timer is a no-op.
            unsafe { ffi::avr_cycle_timer_cancel(state.avr, Some(on_discharged), sensor as *mut c_void) };
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
    buttons: [u8; 2],
    decoded: usize,
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
        let mut state = Box::new(State {
            avr,
            uart: Vec::new(),
            marks: Vec::new(),
            decisions: 0,
            ddr: [0; 2],
            delays: [Some(CLOCK_HZ / 1000); 3],
            sensors: pins::FIELD_SENSORS.map(|pin| RcSensor {
                // SAFETY: `avr` is the core just loaded; a null IRQ is checked below.
                irq: unsafe { ffi::avr_io_getirq(avr, ioctl(b'i', b'o', b'g', pin.port.letter()), c_int::from(pin.bit)) },
            }),
        });
        let state_ptr = &mut *state as *mut State;
        // SAFETY: `avr` is the live core; the callbacks get the boxed state,
        // which `Zumo` drops after the simulator (field order).
        unsafe {
            assert!(state.sensors.iter().all(|s| !s.irq.is_null()), "no field sensor pins");
            // USART1: bytes out, not to stdout.
            let mut flags: u32 = 0;
            ffi::avr_ioctl(avr, ioctl(b'u', b'a', b'g', b'1'), &mut flags as *mut u32 as *mut c_void);
            flags &= !ffi::AVR_UART_FLAG_STDIO;
            ffi::avr_ioctl(avr, ioctl(b'u', b'a', b's', b'1'), &mut flags as *mut u32 as *mut c_void);
            let uart = ffi::avr_io_getirq(avr, ioctl(b'u', b'a', b'r', b'1'), ffi::UART_IRQ_OUTPUT as c_int);
            ffi::avr_irq_register_notify(uart, Some(on_uart), state_ptr as *mut c_void);
            for (port, f) in [(Port::F, on_ddr_f as unsafe extern "C" fn(_, _, _)), (Port::D, on_ddr_d)] {
                let irq = ffi::avr_io_getirq(
                    avr,
                    ioctl(b'i', b'o', b'g', port.letter()),
                    ffi::IOPORT_IRQ_DIRECTION_ALL as c_int,
                );
                ffi::avr_irq_register_notify(irq, Some(f), state_ptr as *mut c_void);
            }
            ffi::avr_register_io_write(avr, GPIOR0, Some(on_gpior0), state_ptr as *mut c_void);
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
        let mut zumo = Zumo { tester, state, pixy: pixy.clone(), buttons: [0; 2], decoded: 0 };
        zumo.tester.twi0().attach_slave_fn(move |p| pixy.borrow_mut().on_packet(p));
        zumo.set_button(pins::BUTTON_A, false);
        zumo.set_button(pins::BUTTON_B_LED_GREEN, false);
        zumo
    }

    /// Stores bytes in the simulated EEPROM.
    pub fn write_eeprom(&mut self, offset: u16, bytes: &[u8]) {
        let mut copy = bytes.to_vec();
        let mut desc = EepromDesc { ee: copy.as_mut_ptr(), offset, size: copy.len() as u32 };
        // SAFETY: simavr copies `size` bytes from `ee`, which holds them.
        let r = unsafe { ffi::avr_ioctl(self.state.avr, ioctl(b'e', b'e', b's', b'p'), &mut desc as *mut _ as *mut c_void) };
        assert_eq!(r, 0, "EEPROM write refused");
    }

    /// Reads bytes of the simulated EEPROM.
    pub fn read_eeprom(&mut self, offset: u16, len: usize) -> Vec<u8> {
        let mut desc = EepromDesc { ee: null_mut(), offset, size: len as u32 };
        // SAFETY: simavr points `ee` at its EEPROM at `offset`.
        let r = unsafe { ffi::avr_ioctl(self.state.avr, ioctl(b'e', b'e', b'g', b'p'), &mut desc as *mut _ as *mut c_void) };
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
        let mut p = self.pixy.borrow_mut();
        p.scene = blocks.to_vec();
        p.bytes.clear();
        p.changed = true;
    }

    /// Connects or disconnects the Pixy (disconnected: it NACKs its address).
    pub fn connect_pixy(&mut self, present: bool) {
        let mut p = self.pixy.borrow_mut();
        p.present = present;
        p.bytes.clear();
    }

    fn set_button(&mut self, pin: Pin, pressed: bool) {
        let (port, bit) = (pin.port.letter(), pin.bit);
        let slot = usize::from(pin.port == Port::D);
        self.buttons[slot] |= pin.mask();
        let mut ext = ffi::avr_ioport_external_t {
            _bitfield_align_1: [],
            _bitfield_1: Default::default(),
            __bindgen_padding_0: Default::default(),
        };
        ext.set_name(u64::from(port));
        ext.set_mask(u64::from(self.buttons[slot]));
        // Pull-ups make released buttons read high.
        ext.set_value(if pressed { u64::from(self.buttons[slot] & !(1 << bit)) } else { u64::from(self.buttons[slot]) });
        // SAFETY: the core is live; `ext` is the ioport's external-state record.
        unsafe {
            ffi::avr_ioctl(self.state.avr, ioctl(b'i', b'o', b'p', port), &mut ext as *mut _ as *mut c_void);
            let irq = ffi::avr_io_getirq(self.state.avr, ioctl(b'i', b'o', b'g', port), c_int::from(bit));
            ffi::avr_raise_irq(irq, u32::from(!pressed));
        }
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

    /// Presses button B and plays the calibration sweep: the robot spins
    /// over bright (100 ticks) and dark (400 ticks) field, alternating every
    /// 20 ms period, until the sweep ends (215 periods).
    pub fn calibrate(&mut self) {
        self.press_b();
        for i in 0..215u16 {
            let t = if i % 2 == 0 { 100 } else { 400 };
            self.set_sensor_ticks([Some(t), Some(t + 10), Some(t + 20)]);
            self.run_ms(20);
        }
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
            self.tester.run();
            // SAFETY: as above.
            assert!(unsafe { (*self.state.avr).cycle } < deadline, "no decision within 100 ms");
        }
        self.state.decisions
    }

    fn data(&self, addr: usize) -> u8 {
        assert!(addr < RAM_END, "data address {addr:#x} outside the 32U4's data space");
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
        (b & pins::DIR_LEFT.mask() != 0, b & pins::DIR_RIGHT.mask() != 0)
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
        (STATICS_END..RAM_END).find(|a| self.data(*a) != PAINT).unwrap_or(RAM_END)
    }

    /// The word at SRAM 0x0800 (the bootloader's key).
    pub fn boot_key(&self) -> u16 {
        self.word(0x0800)
    }

    /// Every byte the firmware has sent on USART1 since boot: the raw
    /// serial stream a host would receive (for the monitor and replay tests).
    pub fn uart_bytes(&self) -> &[u8] {
        &self.state.uart
    }

    /// Log frames received since the last call, decoded with `shared`.
    pub fn frames(&mut self) -> Vec<Result<LogFrame, LogError>> {
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
        self.state.marks.windows(2).filter(|w| w[0].0 == 1 && w[1].0 == 2).map(|w| w[1].1 - w[0].1).collect()
    }
}
