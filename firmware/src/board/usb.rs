//! The USB serial port on the ATmega32U4's USB controller: the register
//! side of the minimal CDC-ACM device in `firmware::usb` (which decides the
//! answers; this module moves the bytes).
//!
//! Polled, never in an interrupt: the control loop calls
//! [`UsbPort::service`] while it waits (for the next period, once per TWI
//! step, while an EEPROM write completes), so the RC timing of the field sensors and
//! the encoder interrupts are never delayed by USB work, and no USB state
//! is shared with an interrupt. One service call, in order:
//!
//! 1. VBUS (USBSTA.VBUS): cable plugged in -> attach (UDCON.DETACH = 0);
//!    pulled -> detach, forget the host's state, drop the queued frames,
//!    and do nothing more until it returns (the robot also runs on
//!    batteries alone);
//! 2. bus events (UDINT): reset -> endpoint 0 set up again, the port
//!    unconfigured; suspend -> the controller's clock frozen and the PLL
//!    off; wake-up -> the PLL on, and the clock unfrozen once it has
//!    locked (a later service if not at once); the robot drives on either way;
//! 3. endpoint 0: a setup packet is read and answered (`Control::setup`);
//!    an IN data stage goes out 64 bytes at a time, each packet when the
//!    bank is free (TXINI); SET_ADDRESS's address is enabled once its
//!    acknowledgement went out (waited for, 150 us at most, within
//!    the service); the SET_LINE_CODING data stage is read; SET_FEATURE /
//!    CLEAR_FEATURE(ENDPOINT_HALT) set STALLRQ / clear it with STALLRQC
//!    and reset the data toggle (RSTDT);
//! 4. once configured: bytes the host sent to the port (bulk OUT) are
//!    dropped, and the next packet of the log queue goes into the bulk IN
//!    endpoint if the host holds the port open (DTR), has not halted it,
//!    and its bank is free;
//! 5. the touch: 1200 baud with DTR low -> [`TouchChange::Armed`].
//!
//! Registers (data space addresses, ATmega32U4 datasheet section 22): each
//! flag is cleared by a read-modify-write that writes 0 to it, as LUFA
//! does; the endpoint registers apply to the endpoint UENUM selects.

use core::ptr::{read_volatile, write_volatile};
use firmware::usb::{
    Control, LogQueue, Payload, Reply, Touch, TouchChange, ENDPOINT_CONFIG, IN_EP, OUT_EP, PACKET,
};

const PLLCSR: *mut u8 = 0x49 as *mut u8;
const UHWCON: *mut u8 = 0xD7 as *mut u8;
const USBCON: *mut u8 = 0xD8 as *mut u8;
const USBSTA: *mut u8 = 0xD9 as *mut u8;
const UDCON: *mut u8 = 0xE0 as *mut u8;
const UDINT: *mut u8 = 0xE1 as *mut u8;
const UDADDR: *mut u8 = 0xE3 as *mut u8;
const UEINTX: *mut u8 = 0xE8 as *mut u8;
const UENUM: *mut u8 = 0xE9 as *mut u8;
const UECONX: *mut u8 = 0xEB as *mut u8;
const UECFG0X: *mut u8 = 0xEC as *mut u8;
const UECFG1X: *mut u8 = 0xED as *mut u8;
const UEDATX: *mut u8 = 0xF1 as *mut u8;
const UEBCLX: *mut u8 = 0xF2 as *mut u8;

// PLLCSR
const PINDIV: u8 = 1 << 4; // 16 MHz crystal: divide by 2 into the PLL
const PLLE: u8 = 1 << 1;
const PLOCK: u8 = 1 << 0;
// UHWCON, USBCON, USBSTA
const UVREGE: u8 = 1 << 0;
const USBE: u8 = 1 << 7;
const FRZCLK: u8 = 1 << 5;
const OTGPADE: u8 = 1 << 4;
const VBUS: u8 = 1 << 0;
// UDCON, UDINT, UDADDR
const DETACH: u8 = 1 << 0;
const SUSPI: u8 = 1 << 0;
const EORSTI: u8 = 1 << 3;
const WAKEUPI: u8 = 1 << 4;
const ADDEN: u8 = 1 << 7;
// UEINTX, UECONX
const FIFOCON: u8 = 1 << 7;
const RXSTPI: u8 = 1 << 3;
const RXOUTI: u8 = 1 << 2;
const TXINI: u8 = 1 << 0;
const STALLRQ: u8 = 1 << 5;
const STALLRQC: u8 = 1 << 4;
const RSTDT: u8 = 1 << 3;
const EPEN: u8 = 1 << 0;

/// Polls of TXINI after SET_ADDRESS's status stage is armed (12
/// cycles each in the image: 150 us): the host's IN token for it follows at once,
/// so the address is enabled within the same service, well inside the
/// 2 ms USB 2.0 allows (section 9.2.6.3); a host slower than that gets it
/// at the next service.
const ADDRESS_POLLS: u16 = 200;

fn read(register: *mut u8) -> u8 {
    // SAFETY: `register` is one of the USB controller's registers above.
    unsafe { read_volatile(register) }
}

fn write(register: *mut u8, value: u8) {
    // SAFETY: as in `read`.
    unsafe { write_volatile(register, value) }
}

/// Clears flags of a flag register (write 0 to clear, 1 leaves them).
fn clear(register: *mut u8, flags: u8) {
    write(register, read(register) & !flags);
}

/// Bytes of log frames the port holds for the host: two frames of the
/// usual ~51 bytes, or one of the longest (75) and one more.
const QUEUE: usize = 128;

/// An IN data stage in progress on endpoint 0.
#[derive(Clone, Copy)]
struct DataIn {
    payload: Payload,
    sent: u16,
    len: u16,
    /// The transfer ends with a zero-length packet (its data, shorter
    /// than asked for, filled its last packet).
    zlp: bool,
}

/// The serial port: the host's view of it, endpoint 0's transfer, the log
/// queue and the touch.
pub struct UsbPort {
    serial: &'static str,
    control: Control,
    data_in: Option<DataIn>,
    /// SET_ADDRESS acknowledged: enable this address once the
    /// acknowledgement has gone out.
    address: Option<u8>,
    line_coding_next: bool,
    queue: LogQueue<QUEUE>,
    touch: Touch,
    vbus: bool,
}

/// The port, in static RAM rather than in the control loop's frame.
static mut PORT: Option<UsbPort> = None;

impl UsbPort {
    /// Turns the controller on: pad regulator, controller, PLL (16 MHz
    /// crystal), VBUS pad; detached until VBUS is seen. `serial` is the
    /// USB serial number. The port exists once: `None` on a second call.
    #[allow(
        clippy::mut_from_ref,
        reason = "the port comes from the PORT static, taken once, not from `serial`"
    )]
    pub fn take(serial: &'static str) -> Option<&'static mut UsbPort> {
        // SAFETY: the only reference to PORT ever made: set here, once.
        let slot = unsafe { &mut *core::ptr::addr_of_mut!(PORT) };
        if slot.is_some() {
            return None;
        }
        write(UHWCON, UVREGE);
        write(USBCON, USBE | FRZCLK | OTGPADE);
        write(PLLCSR, PINDIV | PLLE);
        while read(PLLCSR) & PLOCK == 0 {}
        write(USBCON, USBE | OTGPADE);
        write(UDCON, DETACH);
        Some(slot.insert(UsbPort {
            serial,
            control: Control::new(),
            data_in: None,
            address: None,
            line_coding_next: false,
            queue: LogQueue::new(),
            touch: Touch::default(),
            vbus: false,
        }))
    }

    /// Sets up the endpoints of `ENDPOINT_CONFIG` from `from` on (0: the
    /// control endpoint only, after a bus reset; 1: the serial port's, at
    /// SET_CONFIGURATION).
    fn configure(from: usize, to: usize) {
        for &(ep, cfg0, cfg1) in ENDPOINT_CONFIG.get(from..to).unwrap_or(&[]) {
            write(UENUM, ep);
            write(UECONX, EPEN);
            write(UECFG0X, cfg0);
            write(UECFG1X, cfg1);
        }
    }

    /// The host's state forgotten: a bus reset, or the cable pulled.
    fn forget(&mut self) {
        self.control = Control::new();
        self.data_in = None;
        self.address = None;
        self.line_coding_next = false;
        self.queue.clear();
    }

    /// One round of USB work (the module's step list); returns what
    /// happened to the touch.
    pub fn service(&mut self) -> TouchChange {
        let vbus = read(USBSTA) & VBUS != 0;
        if vbus != self.vbus {
            self.vbus = vbus;
            write(UDCON, if vbus { 0 } else { DETACH });
            // a cable pulled while suspended: the PLL back on for the next host
            write(PLLCSR, PINDIV | PLLE);
            self.forget();
        }
        if vbus {
            self.bus_events();
            if read(USBCON) & FRZCLK == 0 {
                self.endpoint0();
                if self.control.configured() {
                    self.data();
                }
            }
        }
        let c = &self.control;
        self.touch.update(c.configured(), c.baud(), c.dtr())
    }

    fn bus_events(&mut self) {
        let events = read(UDINT);
        if events & EORSTI != 0 {
            clear(UDINT, EORSTI);
            self.forget();
            Self::configure(0, 1);
        }
        if events & SUSPI != 0 {
            clear(UDINT, SUSPI);
            write(USBCON, USBE | FRZCLK | OTGPADE);
            write(PLLCSR, PINDIV);
        }
        if events & WAKEUPI != 0 {
            write(PLLCSR, PINDIV | PLLE);
            clear(UDINT, WAKEUPI);
        }
        // Unfrozen once the PLL has locked again after a wake-up.
        if read(USBCON) & FRZCLK != 0 && read(PLLCSR) & PLOCK != 0 {
            write(USBCON, USBE | OTGPADE);
        }
    }

    fn endpoint0(&mut self) {
        write(UENUM, 0);
        let flags = read(UEINTX);
        if flags & RXSTPI != 0 {
            let mut packet = [0u8; 8];
            for b in packet.iter_mut() {
                *b = read(UEDATX);
            }
            clear(UEINTX, RXSTPI | RXOUTI);
            self.data_in = None;
            self.line_coding_next = false;
            match self.control.setup(&packet, self.serial) {
                Reply::In(payload, len) => {
                    let asked = u16::from_le_bytes([packet[6], packet[7]]);
                    self.data_in = Some(DataIn {
                        payload,
                        sent: 0,
                        len,
                        zlp: len < asked && len % PACKET == 0,
                    });
                }
                Reply::Ack => {
                    // a touch this request arms stops the motors before the
                    // host has the acknowledgement (the caller then stores
                    // the key and sets the watchdog)
                    let c = &self.control;
                    if !self.touch.armed() && Touch::arms(c.configured(), c.baud(), c.dtr()) {
                        super::emergency_stop();
                    }
                    clear(UEINTX, TXINI)
                }
                Reply::Address(a) => {
                    write(UDADDR, a);
                    self.address = Some(a);
                    clear(UEINTX, TXINI);
                    for _ in 0..ADDRESS_POLLS {
                        if read(UEINTX) & TXINI != 0 {
                            break;
                        }
                    }
                }
                Reply::Configure => {
                    Self::configure(1, ENDPOINT_CONFIG.len());
                    write(UENUM, 0);
                    clear(UEINTX, TXINI);
                }
                Reply::Halt(ep, halt) => {
                    write(UENUM, ep);
                    write(
                        UECONX,
                        if halt {
                            EPEN | STALLRQ
                        } else {
                            EPEN | STALLRQC | RSTDT
                        },
                    );
                    write(UENUM, 0);
                    clear(UEINTX, TXINI);
                }
                Reply::ReceiveLineCoding => self.line_coding_next = true,
                Reply::Stall => write(UECONX, EPEN | STALLRQ),
            }
        } else if flags & RXOUTI != 0 {
            if self.line_coding_next {
                let mut coding = [0u8; 7];
                let n = usize::from(read(UEBCLX)).min(coding.len());
                for b in coding.iter_mut().take(n) {
                    *b = read(UEDATX);
                }
                self.control.line_coding_out(coding.get(..n).unwrap_or(&[]));
                self.line_coding_next = false;
                clear(UEINTX, RXOUTI);
                clear(UEINTX, TXINI);
            } else {
                // The status stage of an IN transfer.
                self.data_in = None;
                clear(UEINTX, RXOUTI);
            }
        }
        if read(UEINTX) & TXINI != 0 {
            if let Some(a) = self.address.take() {
                write(UDADDR, a | ADDEN);
            }
            self.next_in_packet();
        }
    }

    /// The next packet of endpoint 0's IN data stage, if one is due.
    fn next_in_packet(&mut self) {
        let Some(mut d) = self.data_in else {
            return;
        };
        if d.sent >= d.len && !d.zlp {
            return;
        }
        let n = (d.len - d.sent).min(PACKET);
        for i in d.sent..d.sent + n {
            write(UEDATX, d.payload.byte(usize::from(i)));
        }
        clear(UEINTX, TXINI);
        if n == 0 {
            d.zlp = false;
        }
        d.sent += n;
        self.data_in = Some(d);
    }

    fn data(&mut self) {
        write(UENUM, OUT_EP);
        if read(UEINTX) & RXOUTI != 0 {
            clear(UEINTX, RXOUTI);
            clear(UEINTX, FIFOCON); // the host's bytes, dropped
        }
        if !self.control.dtr() {
            self.queue.clear();
            return;
        }
        if self.control.halted(IN_EP) {
            return; // the queue fills and drops whole frames until cleared
        }
        write(UENUM, IN_EP);
        if read(UEINTX) & TXINI == 0 {
            return;
        }
        if let Some(packet) = self.queue.packet(usize::from(PACKET)) {
            clear(UEINTX, TXINI);
            for &b in packet {
                write(UEDATX, b);
            }
            clear(UEINTX, FIFOCON);
            let n = packet.len();
            self.queue.sent(n, usize::from(PACKET));
        }
    }

    /// Queues a log frame for the host if it holds the port open (DTR):
    /// whole, or dropped when the host has not read the frames before it.
    pub fn send(&mut self, frame: &[u8]) {
        if self.vbus && self.control.configured() && self.control.dtr() {
            self.queue.push(frame);
        }
    }
}
