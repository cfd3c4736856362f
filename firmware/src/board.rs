//! Register access for the Zumo 32U4 (ATmega32U4, 16 MHz): the only
//! module with `unsafe` and `avr-device`. Pins come from `firmware::pins`;
//! the timers are set up as Pololu's Zumo 32U4 library sets them (motors)
//! or as this table says; everything else is in the library.
//!
//! | what                | where                                      |
//! |---------------------|--------------------------------------------|
//! | motors              | Timer1 mode 8, TOP (ICR1) 400 = 20 kHz; OCR1A/PB5 right, OCR1B/PB6 left; DIR PB1 right, PB2 left |
//! | field sensors       | PF7 left (DN1), PF4 mid (DN3), PD6 right (DN5); emitters (LEDON, PB7) off |
//! | clock               | Timer3 free-running at clk/64 (4 us ticks): control period and RC timing |
//! | Pixy                | TWI master 100 kHz, address 0x54, one 2-byte read per word; a stuck bus is freed by clocking SCL by hand |
//! | encoders            | left XOR PB4 (PCINT0 vector), B PE2; right XOR PE6 (INT6, any edge), B PF0; pulled-up inputs |
//! | log                 | USART1 TX (PD3), 115200 8N1, U2X1, fed from `firmware::log_queue` |
//! | buttons             | A PB3, B PD5 (shared with the green LED), both active low |
//! | LEDs                | yellow PC7 (high = on), green PD5 and red PB0 (low = on) |
//! | markers             | GPIOR0 (simulator cycle counting): 4 at a period's start, 1 before a decision, 2 after the motor writes, 3 after the log frame is sent |
//! | identity            | `shared::FirmwareIdentity` record in flash: robot id and policy CRC |
//! | USB serial port     | the USB controller, polled (`board::usb`): while waiting for the next period, once per TWI step, while an EEPROM write completes; each service first moves a queued log byte into USART1 |
//!
//! Interrupts: only the two encoder interrupts are enabled; the timed
//! sequences (watchdog, EEPROM) and the reads of the counts run with
//! interrupts off.

mod usb;

use avr_device::atmega32u4::Peripherals;
use avr_device::interrupt::{self, Mutex};
use core::arch::asm;
use core::cell::{Cell, RefCell};
use firmware::camera::{BusError, WordSource};
use firmware::config::{PERIOD_TICKS, RC_CHARGE_US, TICK_US, TWI_TIMEOUT_TICKS, USB_QUIET_TICKS};
use firmware::embedded;
use firmware::log_queue::LogQueue;
use firmware::odometry::Quadrature;
use firmware::pins;
use firmware::rc::Discharge;
use firmware::supervisor::{Buttons, Leds};
use firmware::usb::{TouchChange, BOOT_KEY};
use shared::{DriveOutputs, FieldScales};

/// The policy's best-action sets, in flash (read with `lpm`, never copied to SRAM).
#[link_section = ".progmem.data"]
static POLICY: [u8; embedded::POLICY_SETS.len()] = embedded::POLICY_SETS;

/// The image's identity record (robot id, policy CRC), in flash; `host
/// flash` finds it in the hex before writing it.
#[link_section = ".progmem.data"]
static IDENTITY: [u8; shared::FirmwareIdentity::LEN] = embedded::IDENTITY;

/// Reads a byte of program memory.
fn flash_byte(addr: *const u8) -> u8 {
    let byte: u8;
    // SAFETY: `lpm` reads program memory at Z; callers pass addresses of flash statics.
    unsafe { asm!("lpm {0}, Z", out(reg) byte, in("Z") addr, options(pure, readonly, nostack)) };
    byte
}

/// The robot id of this build, from the identity record in flash.
pub fn robot_id() -> u8 {
    flash_byte(
        IDENTITY
            .as_ptr()
            .wrapping_add(shared::FirmwareIdentity::ROBOT_ID_OFFSET),
    )
}

/// The left and right encoders, updated by their interrupts.
static LEFT_ENCODER: Mutex<Cell<Quadrature>> = Mutex::new(Cell::new(Quadrature::new(false, false)));
static RIGHT_ENCODER: Mutex<Cell<Quadrature>> =
    Mutex::new(Cell::new(Quadrature::new(false, false)));

/// I/O addresses of the pin registers the encoder interrupts read.
const PINB: *const u8 = 0x23 as *const u8;
const PINE: *const u8 = 0x2C as *const u8;
const PINF: *const u8 = 0x2F as *const u8;

fn pin_high(register: *const u8, mask: u8) -> bool {
    // SAFETY: a read of an I/O register, which has no side effects.
    unsafe { core::ptr::read_volatile(register) & mask != 0 }
}

/// One encoder edge, in its interrupt (interrupts are off there).
#[inline(always)]
fn encoder_edge(encoder: &Mutex<Cell<Quadrature>>, xor: bool, b: bool) {
    // SAFETY: called only from an interrupt handler, which runs with interrupts disabled.
    let cs = unsafe { interrupt::CriticalSection::new() };
    let cell = encoder.borrow(cs);
    let mut q = cell.get();
    q.edge(xor, b);
    cell.set(q);
}

#[avr_device::interrupt(atmega32u4)]
fn PCINT0() {
    encoder_edge(
        &LEFT_ENCODER,
        pin_high(PINB, ENCODER_LEFT_XOR),
        pin_high(PINE, ENCODER_LEFT_B),
    );
}

#[avr_device::interrupt(atmega32u4)]
fn INT6() {
    encoder_edge(
        &RIGHT_ENCODER,
        pin_high(PINE, ENCODER_RIGHT_XOR),
        pin_high(PINF, ENCODER_RIGHT_B),
    );
}

/// The flash-resident policy table, readable by the decision.
pub struct FlashPolicy;

impl firmware::decision::PolicyBytes for FlashPolicy {
    fn byte(&self, index: usize) -> u8 {
        // Masked into the table (its length is a power of two).
        flash_byte(POLICY.as_ptr().wrapping_add(index & (POLICY.len() - 1)))
    }
}

// Pin bits (the Zumo's pin map, `firmware::pins`).
const LED_RED: u8 = pins::LED_RED.mask();
const DIR_RIGHT: u8 = pins::DIR_RIGHT.mask();
const DIR_LEFT: u8 = pins::DIR_LEFT.mask();
const BUTTON_A: u8 = pins::BUTTON_A.mask();
const PWM_RIGHT: u8 = pins::PWM_RIGHT.mask();
const PWM_LEFT: u8 = pins::PWM_LEFT.mask();
const EMITTERS: u8 = pins::EMITTERS.mask();
const LED_YELLOW: u8 = pins::LED_YELLOW.mask();
const BUTTON_B: u8 = pins::BUTTON_B_LED_GREEN.mask();
const SENSOR_LEFT: u8 = pins::FIELD_SENSORS[0].mask(); // on PORTF
const SENSOR_MID: u8 = pins::FIELD_SENSORS[1].mask(); // on PORTF
const SENSOR_RIGHT: u8 = pins::FIELD_SENSORS[2].mask(); // on PORTD
const ENCODER_LEFT_XOR: u8 = pins::ENCODER_LEFT_XOR.mask(); // on PORTB
const ENCODER_LEFT_B: u8 = pins::ENCODER_LEFT_B.mask(); // on PORTE
const ENCODER_RIGHT_XOR: u8 = pins::ENCODER_RIGHT_XOR.mask(); // on PORTE
const ENCODER_RIGHT_B: u8 = pins::ENCODER_RIGHT_B.mask(); // on PORTF
const SCL: u8 = pins::I2C_SCL.mask(); // on PORTD
const SDA: u8 = pins::I2C_SDA.mask(); // on PORTD
                                      // Register bits (ATmega32U4 datasheet).
const TWINT: u8 = 1 << 7;
const TWEA: u8 = 1 << 6;
const TWSTA: u8 = 1 << 5;
const TWSTO: u8 = 1 << 4;
const TWEN: u8 = 1 << 2;
// TWI status codes (TWSR & 0xF8), master receiver.
const TW_START: u8 = 0x08;
const TW_REP_START: u8 = 0x10;
const TW_SLA_ACK: u8 = 0x40;
const TW_SLA_NACK: u8 = 0x48;
const TW_DATA_ACK: u8 = 0x50;
const TW_DATA_NACK: u8 = 0x58;
/// Clock pulses that free any slave holding SDA (it sends at most 8 more bits).
const RECOVERY_CLOCKS: u8 = 9;
const PIXY_READ: u8 = (pins::PIXY_ADDRESS << 1) | 1;
const WDE: u8 = 1 << 3;
const WDCE: u8 = 1 << 4;
const WDP2: u8 = 1 << 2; // with WDP1..0 = 0: 250 ms
const WDP1_0: u8 = 0b11; // with WDP2 = 0: 125 ms, the touch's reset

/// The bootloader enters itself after a watchdog reset when this word holds
/// 0x7777 (`firmware::usb::BOOT_KEY`); the firmware clears it at start-up
/// and writes it only for a 1200-baud touch.
const BOOT_KEY_AT: *mut u16 = firmware::usb::BOOT_KEY_ADDR as *mut u16;

/// The log queue. Only `Board::send` and `Board::feed_usart` call this,
/// from the control loop (never from an interrupt), and neither keeps the
/// reference past its own statement: no two references are ever live.
fn log_queue() -> &'static mut LogQueue<LOG_QUEUE_LEN> {
    // SAFETY: see above.
    unsafe { &mut *core::ptr::addr_of_mut!(LOG_QUEUE) }
}

/// The peripherals, the control period's clock and the USB serial port.
pub struct Board {
    dp: Peripherals,
    period_start: u16,
    usb: RefCell<Option<&'static mut usb::UsbPort>>,
    /// A 1200-baud touch is pending: motors stopped, key stored, the
    /// watchdog (125 ms) no longer fed.
    touched: Cell<bool>,
}

/// The field sensors' calibration curves: 246 bytes, kept in static RAM
/// rather than on the stack, which must stay above the bootloader key at
/// 0x0800 (`tests/tests/firmware_smoke.rs` checks).
static mut FIELD_SCALES: FieldScales = FieldScales::UNSET;

/// Room for two of the longest log frames: one going out while the next
/// period queues its own.
const LOG_QUEUE_LEN: usize = 2 * shared::LogFrame::MAX_ENCODED_LEN;

/// The log frames waiting for USART1, in static RAM. Reached only through
/// [`log_queue`] (not a field of `Board`: the board lives in the control
/// loop's stack frame, which has no bytes to spare).
static mut LOG_QUEUE: LogQueue<LOG_QUEUE_LEN> = LogQueue::new();

impl Board {
    /// First thing at start-up: stop the watchdog a reset may have left
    /// running (with the shortest timeout) and clear the bootloader key.
    /// Returns the board and the calibration curves' storage.
    pub fn take() -> (Board, &'static mut FieldScales) {
        // SAFETY: called once, before anything else touches the peripherals.
        let dp = unsafe { Peripherals::steal() };
        avr_device::asm::wdr();
        dp.CPU.mcusr().write(|w| unsafe { w.bits(0) }); // WDRF forces WDE on until cleared
                                                        // SAFETY: timed sequence (<= 4 cycles): set WDCE|WDE, then write 0
                                                        // (interrupts are not enabled yet).
        unsafe {
            asm!(
                "sts 0x60, {ce}",
                "sts 0x60, {zero}",
                ce = in(reg) WDCE | WDE,
                zero = in(reg) 0u8,
                options(nostack),
            );
            core::ptr::write_volatile(BOOT_KEY_AT, 0);
        }
        // SAFETY: `take` runs once, so this is the only reference ever made.
        let scales = unsafe { &mut *core::ptr::addr_of_mut!(FIELD_SCALES) };
        (
            Board {
                dp,
                period_start: 0,
                usb: RefCell::new(None),
                touched: Cell::new(false),
            },
            scales,
        )
    }

    /// Sets up pins, timers, TWI and the USART.
    pub fn init(&mut self) {
        let dp = &self.dp;
        // Timer3: free running, clk/64.
        dp.TC3.tccr3a().write(|w| unsafe { w.bits(0) });
        dp.TC3.tccr3b().write(|w| unsafe { w.bits(0b011) });
        // Motors: outputs low; Timer1 mode 8 (phase and frequency correct,
        // TOP = ICR1 = 400), non-inverting OC1A/OC1B, clk/1: 20 kHz.
        // A and the left encoder's XOR pulled up, red LED off, LEDON low.
        dp.PORTB
            .portb()
            .write(|w| unsafe { w.bits(BUTTON_A | LED_RED | ENCODER_LEFT_XOR) });
        dp.PORTB.ddrb().write(|w| unsafe {
            w.bits(LED_RED | DIR_RIGHT | DIR_LEFT | PWM_RIGHT | PWM_LEFT | EMITTERS)
        });
        dp.TC1.tccr1a().write(|w| unsafe { w.bits(0b1010_0000) });
        dp.TC1.tccr1b().write(|w| unsafe { w.bits(0b0001_0001) });
        dp.TC1.icr1().write(|w| w.set(400));
        dp.TC1.ocr1a().write(|w| w.set(0));
        dp.TC1.ocr1b().write(|w| w.set(0));
        // LEDs: yellow off, green off (its pin high).
        dp.PORTC.ddrc().write(|w| unsafe { w.bits(LED_YELLOW) });
        dp.PORTD.portd().write(|w| unsafe { w.bits(BUTTON_B) });
        dp.PORTD.ddrd().write(|w| unsafe { w.bits(BUTTON_B) });
        // TWI: 100 kHz = 16 MHz / (16 + 2 x 72), prescaler 1.
        dp.TWI.twsr().write(|w| unsafe { w.bits(0) });
        dp.TWI.twbr().write(|w| unsafe { w.bits(72) });
        dp.TWI.twcr().write(|w| unsafe { w.bits(TWEN) });
        // Encoders: pulled-up inputs (PORTE, PF0; PB4 above); pin change
        // interrupt on PB4 only, INT6 on any edge.
        dp.PORTE
            .porte()
            .write(|w| unsafe { w.bits(ENCODER_LEFT_B | ENCODER_RIGHT_XOR) });
        dp.PORTF
            .portf()
            .modify(|r, w| unsafe { w.bits(r.bits() | ENCODER_RIGHT_B) });
        dp.EXINT
            .pcmsk0()
            .write(|w| unsafe { w.bits(ENCODER_LEFT_XOR) });
        dp.EXINT.pcicr().write(|w| unsafe { w.bits(1) }); // PCIE0
        dp.EXINT.eicrb().write(|w| unsafe { w.bits(0b01 << 4) }); // ISC61..60 = 01: any edge
        dp.EXINT.pcifr().write(|w| unsafe { w.bits(1) });
        dp.EXINT.eifr().write(|w| unsafe { w.bits(1 << 6) });
        dp.EXINT.eimsk().write(|w| unsafe { w.bits(1 << 6) });
        interrupt::free(|cs| {
            let left = Quadrature::new(
                pin_high(PINB, ENCODER_LEFT_XOR),
                pin_high(PINE, ENCODER_LEFT_B),
            );
            let right = Quadrature::new(
                pin_high(PINE, ENCODER_RIGHT_XOR),
                pin_high(PINF, ENCODER_RIGHT_B),
            );
            LEFT_ENCODER.borrow(cs).set(left);
            RIGHT_ENCODER.borrow(cs).set(right);
        });
        // USART1: 115200 8N1, U2X1 first, then UBRR1 = 16 (117.6 kbaud, +2.1 %).
        dp.USART1.ucsr1a().write(|w| unsafe { w.bits(1 << 1) });
        dp.USART1.ubrr1().write(|w| w.set(16));
        dp.USART1.ucsr1c().write(|w| unsafe { w.bits(0b0000_0110) });
        dp.USART1.ucsr1b().write(|w| unsafe { w.bits(1 << 3) }); // TXEN1
        self.period_start = self.now();
        // SAFETY: the encoder state is initialised; nothing else uses interrupts.
        unsafe { interrupt::enable() };
    }

    /// Turns the USB controller on: the serial port `serial` (the robot's
    /// USB serial number) attaches once VBUS is seen.
    pub fn usb_init(&mut self, serial: &'static str) {
        *self.usb.get_mut() = usb::UsbPort::take(serial);
    }

    /// One round of USB work (`board::usb`), and the touch it may bring:
    /// armed, the motors stop, the bootloader's key is stored and the
    /// watchdog is set to 125 ms and no longer fed; cancelled, the key is
    /// cleared and the control loop's watchdog (250 ms) is back.
    fn serve_usb(&self) {
        self.feed_usart();
        let Ok(mut port) = self.usb.try_borrow_mut() else {
            return;
        };
        let Some(port) = port.as_mut() else {
            return;
        };
        match port.service() {
            TouchChange::None => {}
            TouchChange::Armed => {
                emergency_stop();
                // SAFETY: 0x0800 is SRAM above the statics and below the
                // stack's budget (tests/tests/firmware_smoke.rs checks both).
                unsafe { core::ptr::write_volatile(BOOT_KEY_AT, BOOT_KEY) };
                self.touched.set(true);
                self.watchdog(WDE | WDP1_0);
            }
            TouchChange::Cancelled => {
                // SAFETY: as above.
                unsafe { core::ptr::write_volatile(BOOT_KEY_AT, 0) };
                self.touched.set(false);
                self.watchdog(WDE | WDP2);
            }
        }
    }

    /// Whether a 1200-baud touch is pending: the control loop then leaves
    /// the motors stopped and does nothing but wait for the watchdog.
    pub fn touched(&self) -> bool {
        self.touched.get()
    }

    /// Queues a log frame for the USB serial port (sent if a host holds
    /// it open; dropped whole if the host stopped reading).
    pub fn send_usb(&self, frame: &[u8]) {
        if let Ok(mut port) = self.usb.try_borrow_mut() {
            if let Some(port) = port.as_mut() {
                port.send(frame);
            }
        }
        self.serve_usb();
    }

    /// The encoder counts (left, right) since the last call.
    pub fn take_encoder_counts(&self) -> [i16; 2] {
        interrupt::free(|cs| {
            [&LEFT_ENCODER, &RIGHT_ENCODER].map(|encoder| {
                let cell = encoder.borrow(cs);
                let mut q = cell.get();
                let n = q.take();
                cell.set(q);
                n
            })
        })
    }

    /// Enables the watchdog (250 ms) for the control loop.
    pub fn watchdog_on(&mut self) {
        self.watchdog(WDE | WDP2);
    }

    /// Sets the watchdog to `setting` (WDTCSR: WDE + prescaler) and feeds
    /// it, before and after: the new timeout counts from the change.
    fn watchdog(&self, setting: u8) {
        avr_device::asm::wdr();
        // SAFETY: timed sequence (<= 4 cycles, interrupts off): WDCE|WDE, then the setting.
        interrupt::free(|_| unsafe {
            asm!(
                "sts 0x60, {ce}",
                "sts 0x60, {on}",
                ce = in(reg) WDCE | WDE,
                on = in(reg) setting,
                options(nostack),
            );
        });
        avr_device::asm::wdr();
    }

    /// Timer3 now, in 4 us ticks.
    fn now(&self) -> u16 {
        self.dp.TC3.tcnt3().read().bits()
    }

    /// Busy-waits (simavr cannot wake from SLEEP) until `ticks` have passed since `from`.
    fn wait_until(&self, from: u16, ticks: u16) {
        while self.now().wrapping_sub(from) < ticks {}
    }

    /// Waits for the next control period, serving USB but for its last
    /// [`USB_QUIET_TICKS`] (so that it starts on time), and feeds the
    /// watchdog unless a touch is pending. After an overrun the schedule
    /// restarts from now rather than catching up.
    pub fn wait_period(&mut self) {
        let next = self.period_start.wrapping_add(PERIOD_TICKS);
        if self.now().wrapping_sub(self.period_start) >= PERIOD_TICKS {
            self.period_start = self.now();
        } else {
            while self.now().wrapping_sub(self.period_start) < PERIOD_TICKS - USB_QUIET_TICKS {
                self.serve_usb();
            }
            self.wait_until(self.period_start, PERIOD_TICKS);
            self.period_start = next;
        }
        self.feed_watchdog();
    }

    /// Feeds the watchdog (long operations: EEPROM writes), unless a
    /// touch is pending.
    pub fn feed_watchdog(&self) {
        if !self.touched.get() {
            avr_device::asm::wdr();
        }
    }

    /// Reads both buttons. B shares its pin with the green LED: the pin becomes
    /// a pulled-up input for a few microseconds, then is restored.
    pub fn buttons(&self) -> Buttons {
        let d = &self.dp.PORTD;
        let a = self.dp.PORTB.pinb().read().bits() & BUTTON_A == 0;
        let (ddr, port) = (d.ddrd().read().bits(), d.portd().read().bits());
        d.ddrd().write(|w| unsafe { w.bits(ddr & !BUTTON_B) });
        d.portd().write(|w| unsafe { w.bits(port | BUTTON_B) });
        let t = self.now();
        self.wait_until(t, 2);
        let b = d.pind().read().bits() & BUTTON_B == 0;
        d.portd().write(|w| unsafe { w.bits(port) });
        d.ddrd().write(|w| unsafe { w.bits(ddr) });
        Buttons { a, b }
    }

    /// Times the three field sensors' RC discharge: charge them for 10 us,
    /// make them inputs (no pull-up), then poll them together against
    /// Timer3 until all read low or 2000 us passed. Out of line on purpose:
    /// inlined into the control loop's large stack frame, every access to
    /// the measurement went through the frame pointer and one poll took
    /// about three Timer3 ticks (the equivalence tests measured the raw
    /// times 0 to 3 ticks late); in its own small frame, with a loop that
    /// only samples, a poll takes about half a tick.
    #[inline(never)]
    pub fn field_sensors(&self) -> [u16; 3] {
        let (f, d) = (&self.dp.PORTF, &self.dp.PORTD);
        f.portf()
            .modify(|r, w| unsafe { w.bits(r.bits() | SENSOR_LEFT | SENSOR_MID) });
        f.ddrf()
            .modify(|r, w| unsafe { w.bits(r.bits() | SENSOR_LEFT | SENSOR_MID) });
        d.portd()
            .modify(|r, w| unsafe { w.bits(r.bits() | SENSOR_RIGHT) });
        d.ddrd()
            .modify(|r, w| unsafe { w.bits(r.bits() | SENSOR_RIGHT) });
        let t = self.now();
        self.wait_until(t, RC_CHARGE_US.div_ceil(TICK_US) + 1);
        // Inputs without pull-up, with interrupts off for these few cycles:
        // an encoder interrupt between a DDR and its PORT write would leave
        // the pull-up on while the sensor discharges.
        interrupt::free(|_| {
            f.ddrf()
                .modify(|r, w| unsafe { w.bits(r.bits() & !(SENSOR_LEFT | SENSOR_MID)) });
            f.portf()
                .modify(|r, w| unsafe { w.bits(r.bits() & !(SENSOR_LEFT | SENSOR_MID)) });
            d.ddrd()
                .modify(|r, w| unsafe { w.bits(r.bits() & !SENSOR_RIGHT) });
            d.portd()
                .modify(|r, w| unsafe { w.bits(r.bits() & !SENSOR_RIGHT) });
        });
        // Poll: only sample the pins and the timer; `Discharge` notes when a
        // sensor is first seen low and works the times out afterwards.
        let mut discharge = Discharge::start(self.now());
        loop {
            let (pf, pd) = (f.pinf().read().bits(), d.pind().read().bits());
            let now = self.now();
            let low = u8::from(pf & SENSOR_LEFT == 0)
                | u8::from(pf & SENSOR_MID == 0) << 1
                | u8::from(pd & SENSOR_RIGHT == 0) << 2;
            if discharge.sample(now, low) {
                break;
            }
        }
        discharge.times()
    }

    /// Applies motor outputs: OCR1A and DIR_RIGHT right, OCR1B and DIR_LEFT left.
    pub fn set_motors(&self, out: &DriveOutputs) {
        let b = &self.dp.PORTB;
        let mut dir = 0;
        if out.right.dir_high {
            dir |= DIR_RIGHT;
        }
        if out.left.dir_high {
            dir |= DIR_LEFT;
        }
        b.portb()
            .modify(|r, w| unsafe { w.bits((r.bits() & !(DIR_RIGHT | DIR_LEFT)) | dir) });
        self.dp.TC1.ocr1a().write(|w| w.set(out.right.duty));
        self.dp.TC1.ocr1b().write(|w| w.set(out.left.duty));
    }

    /// Writes a marker (GPIOR0) the simulator tests watch (see the module table).
    #[inline(always)]
    pub fn mark(&self, value: u8) {
        self.dp.CPU.gpior0().write(|w| unsafe { w.bits(value) });
    }

    /// Lights the LEDs.
    pub fn leds(&self, leds: Leds) {
        let (b, c, d) = (&self.dp.PORTB, &self.dp.PORTC, &self.dp.PORTD);
        c.portc().modify(|r, w| unsafe {
            w.bits(if leds.yellow {
                r.bits() | LED_YELLOW
            } else {
                r.bits() & !LED_YELLOW
            })
        });
        b.portb().modify(|r, w| unsafe {
            w.bits(if leds.red {
                r.bits() & !LED_RED
            } else {
                r.bits() | LED_RED
            })
        });
        d.portd().modify(|r, w| unsafe {
            w.bits(if leds.green {
                r.bits() & !BUTTON_B
            } else {
                r.bits() | BUTTON_B
            })
        });
    }

    /// Queues a log frame for USART1 (`firmware::log_queue`: dropped
    /// whole and counted if the queue is full); it goes out a byte at a
    /// time while the loop waits.
    pub fn send(&self, frame: &[u8]) {
        log_queue().push_frame(frame);
        self.feed_usart();
    }

    /// Moves the next queued log byte into USART1 if its data register is
    /// empty. Out of line: inlined into `serve_usb` it deepened the stack
    /// under USB's service, the firmware's deepest chain.
    #[inline(never)]
    fn feed_usart(&self) {
        let u = &self.dp.USART1;
        if u.ucsr1a().read().bits() & (1 << 5) == 0 {
            return; // UDRE1: the last byte is still in the data register
        }
        if let Some(byte) = log_queue().pop() {
            u.udr1().write(|w| unsafe { w.bits(byte) });
        }
    }

    /// Reads `out.len()` bytes of EEPROM from `addr`.
    pub fn eeprom_read(&self, addr: u16, out: &mut [u8]) {
        let e = &self.dp.EEPROM;
        for (i, byte) in out.iter_mut().enumerate() {
            while e.eecr().read().bits() & (1 << 1) != 0 {} // EEPE
            e.eear().write(|w| w.set(addr + i as u16));
            e.eecr().write(|w| unsafe { w.bits(1 << 0) }); // EERE
            *byte = e.eedr().read().bits();
        }
    }

    /// Writes bytes to EEPROM at `addr` (3.4 ms per byte; feeds the watchdog).
    pub fn eeprom_write(&self, addr: u16, bytes: &[u8]) {
        let e = &self.dp.EEPROM;
        for (i, byte) in bytes.iter().enumerate() {
            while e.eecr().read().bits() & (1 << 1) != 0 {
                self.feed_watchdog();
                self.serve_usb();
            }
            e.eear().write(|w| w.set(addr + i as u16));
            e.eedr().write(|w| unsafe { w.bits(*byte) });
            // SAFETY: timed sequence (<= 4 cycles, interrupts off): EEMPE,
            // then EEPE, in EECR (I/O 0x1F).
            interrupt::free(|_| unsafe { asm!("sbi 0x1f, 2", "sbi 0x1f, 1", options(nostack)) });
        }
    }

    /// Waits for TWINT, or gives up after [`TWI_TIMEOUT_TICKS`] (and
    /// frees the bus); returns TWSR's status.
    fn twi_step(&self, control: u8) -> Result<u8, BusError> {
        let t = &self.dp.TWI;
        t.twcr().write(|w| unsafe { w.bits(control) });
        let start = self.now();
        // USB once per step, while the TWI moves the byte (90 us at 100
        // kHz): serving in the wait itself would delay noticing TWINT.
        self.serve_usb();
        while t.twcr().read().bits() & TWINT == 0 {
            if self.now().wrapping_sub(start) >= TWI_TIMEOUT_TICKS {
                self.twi_recover();
                return Err(BusError::Stalled);
            }
        }
        Ok(t.twsr().read().bits() & 0xF8)
    }

    fn twi_stop(&self) {
        self.dp
            .TWI
            .twcr()
            .write(|w| unsafe { w.bits(TWINT | TWEN | TWSTO) });
        let start = self.now();
        while self.dp.TWI.twcr().read().bits() & TWSTO != 0 {
            if self.now().wrapping_sub(start) >= TWI_TIMEOUT_TICKS {
                self.twi_recover();
                return;
            }
        }
    }

    fn sda_low(&self) -> bool {
        self.dp.PORTD.pind().read().bits() & SDA == 0
    }

    /// Frees a bus whose SDA a slave holds low (it was cut off mid-byte):
    /// with the TWI off, clocks SCL by hand (open drain: driven low, or
    /// released to the pull-up) until SDA is released, at most
    /// [`RECOVERY_CLOCKS`] times, then sends a STOP and turns the TWI back
    /// on. Returns whether SDA is free.
    fn twi_recover(&self) -> bool {
        let d = &self.dp.PORTD;
        self.dp.TWI.twcr().write(|w| unsafe { w.bits(0) });
        d.portd()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(SCL | SDA)) });
        d.ddrd()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(SCL | SDA)) });
        let half_period = || {
            let t = self.now();
            self.wait_until(t, 2);
        };
        for _ in 0..RECOVERY_CLOCKS {
            if !self.sda_low() {
                break;
            }
            d.ddrd().modify(|r, w| unsafe { w.bits(r.bits() | SCL) });
            half_period();
            d.ddrd().modify(|r, w| unsafe { w.bits(r.bits() & !SCL) });
            half_period();
        }
        // STOP: SDA rises while SCL is high.
        d.ddrd().modify(|r, w| unsafe { w.bits(r.bits() | SDA) });
        half_period();
        d.ddrd().modify(|r, w| unsafe { w.bits(r.bits() & !SDA) });
        half_period();
        let free = !self.sda_low();
        self.dp.TWI.twcr().write(|w| unsafe { w.bits(TWEN) });
        free
    }

    /// One read transaction of `N` bytes from the Pixy: START, SLA+R, the
    /// bytes (the last one NACKed), STOP.
    fn twi_read<const N: usize>(&self) -> Result<[u8; N], BusError> {
        let result = self.twi_read_inner::<N>();
        self.twi_stop();
        result
    }

    /// Every step's status is checked: START (or repeated START), SLA+R
    /// acknowledged, each byte received with the acknowledgement asked for.
    fn twi_read_inner<const N: usize>(&self) -> Result<[u8; N], BusError> {
        if self.sda_low() && !self.twi_recover() {
            return Err(BusError::Stuck);
        }
        let status = self.twi_step(TWINT | TWSTA | TWEN)?;
        if status != TW_START && status != TW_REP_START {
            return Err(BusError::Unexpected);
        }
        self.dp.TWI.twdr().write(|w| unsafe { w.bits(PIXY_READ) });
        match self.twi_step(TWINT | TWEN)? {
            TW_SLA_ACK => {}
            TW_SLA_NACK => return Err(BusError::Nack),
            _ => return Err(BusError::Unexpected),
        }
        let mut out = [0u8; N];
        for (i, byte) in out.iter_mut().enumerate() {
            let (ack, expected) = if i + 1 < N {
                (TWEA, TW_DATA_ACK)
            } else {
                (0, TW_DATA_NACK)
            };
            if self.twi_step(TWINT | TWEN | ack)? != expected {
                return Err(BusError::Unexpected);
            }
            *byte = self.dp.TWI.twdr().read().bits();
        }
        Ok(out)
    }
}

impl WordSource for Board {
    fn read_word(&mut self) -> Result<u16, BusError> {
        self.twi_read::<2>().map(u16::from_le_bytes)
    }

    fn skip_byte(&mut self) -> Result<(), BusError> {
        self.twi_read::<1>().map(|_| ())
    }
}

/// Stops the motors from any state (panic handler).
pub fn emergency_stop() {
    // SAFETY: the program is ending; only the motor registers are touched.
    let dp = unsafe { Peripherals::steal() };
    dp.TC1.ocr1a().write(|w| w.set(0));
    dp.TC1.ocr1b().write(|w| w.set(0));
}
