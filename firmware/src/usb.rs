//! The USB serial port's logic, a minimal CDC-ACM device of our own (why
//! not `usb-device`: `docs/firmware.md`): what the board layer's driver
//! for the ATmega32U4's USB controller (`src/board/usb.rs`) decides
//! without touching a register, tested on the host.
//!
//! - [`Control`]: the answer to each setup packet on endpoint 0 (the
//!   standard requests of a device with one configuration, and CDC-ACM's
//!   SET_LINE_CODING, GET_LINE_CODING, SET_CONTROL_LINE_STATE, SEND_BREAK;
//!   anything else stalls), with the descriptors it sends
//!   ([`DEVICE_DESCRIPTOR`], [`CONFIG_DESCRIPTOR`], strings) and the
//!   endpoints the configuration sets up ([`ENDPOINT_CONFIG`]).
//! - [`LogQueue`]: the log frames waiting for the bulk IN endpoint. A frame
//!   goes in whole or not at all (dropped: its tick is missing from the
//!   host's recording, `host replay` counts them), so a host that stops
//!   reading never blocks the control period and never sees half a frame;
//!   it comes out in packets of at most 64 bytes, with a zero-length
//!   packet after a full one that ends the data, which completes the host's
//!   read.
//! - [`Touch`]: the "1200-baud touch" (Arduino's convention): line coding
//!   1200 baud with DTR low arms a reset into the bootloader, anything else
//!   cancels it.
//!
//! Identity: [`VID`] and [`PID`] are the ids Pololu's Arduino builds give a
//! sketch on an A-Star 32U4 or a Zumo 32U4 (`../shared/docs/hardware.md`
//! section 6), the serial number is `robot-NNN` from the robot id
//! (`shared::FirmwareIdentity::usb_serial`).

/// Vendor id: Pololu (the A-Star 32U4 and Zumo 32U4 boards' vendor).
pub const VID: u16 = 0x1FFB;
/// Product id: Pololu's A-Star 32U4 application id, what any sketch built
/// for the Zumo 32U4 presents (its bootloader is 0x0101).
pub const PID: u16 = 0x2300;
/// Manufacturer string.
pub const MANUFACTURER: &str = "zumo-swarm";
/// Product string.
pub const PRODUCT: &str = "Zumo 32U4 robot";
/// Packet size of the control and bulk endpoints.
pub const PACKET: u16 = 64;
/// The line coding's baud rate that, with DTR low, asks for the bootloader.
pub const TOUCH_BAUD: u32 = shared::identity::USB_TOUCH_BAUD;
/// The bootloader enters itself after a watchdog reset when this word is
/// at SRAM [`BOOT_KEY_ADDR`] (`../shared/docs/hardware.md` section 6).
pub const BOOT_KEY: u16 = 0x7777;
/// Where the bootloader looks for [`BOOT_KEY`].
pub const BOOT_KEY_ADDR: u16 = 0x0800;

/// The device descriptor: USB 2.0, class EF/02/01 (a function made of an
/// interface association), endpoint 0 of 64 bytes, [`VID`]/[`PID`],
/// release 1.00, strings 1 (manufacturer), 2 (product), 3 (serial number),
/// one configuration.
pub static DEVICE_DESCRIPTOR: [u8; 18] = {
    let (v, p) = (VID.to_le_bytes(), PID.to_le_bytes());
    [
        18, 1, 0x00, 0x02, 0xEF, 0x02, 0x01, 64, v[0], v[1], p[0], p[1], 0x00, 0x01, 1, 2, 3, 1,
    ]
};

/// The notification endpoint (interrupt IN, 8 bytes).
pub const NOTIFY_EP: u8 = 1;
/// The data endpoint the host writes to (bulk OUT, 64 bytes).
pub const OUT_EP: u8 = 2;
/// The data endpoint the log frames go out on (bulk IN, 64 bytes).
pub const IN_EP: u8 = 3;

/// The configuration descriptor, 75 bytes: bus powered, 100 mA; an
/// interface association of interfaces 0 and 1 (CDC, ACM); interface 0
/// (CDC communication, ACM, no protocol) with its header (CDC 1.10), call
/// management, ACM (capabilities: line coding and control line state) and
/// union functional descriptors and the notification endpoint (interrupt
/// IN 1, 8 bytes, every 255 ms); interface 1 (CDC data) with bulk OUT 2
/// and bulk IN 3, 64 bytes each.
pub static CONFIG_DESCRIPTOR: [u8; 75] = [
    9,
    2,
    75,
    0,
    2,
    1,
    0,
    0x80,
    50, // configuration
    8,
    11,
    0,
    2,
    0x02,
    0x02,
    0x00,
    0, // interface association
    9,
    4,
    0,
    0,
    1,
    0x02,
    0x02,
    0x00,
    0, // interface 0: CDC ACM
    5,
    0x24,
    0x00,
    0x10,
    0x01, // header: CDC 1.10
    5,
    0x24,
    0x01,
    0x00,
    1, // call management: data interface 1
    4,
    0x24,
    0x02,
    0x02, // ACM: line coding and control line state
    5,
    0x24,
    0x06,
    0,
    1, // union: 0 controls 1
    7,
    5,
    0x80 | NOTIFY_EP,
    0x03,
    8,
    0,
    255, // interrupt IN
    9,
    4,
    1,
    0,
    2,
    0x0A,
    0x00,
    0x00,
    0, // interface 1: CDC data
    7,
    5,
    OUT_EP,
    0x02,
    64,
    0,
    0, // bulk OUT
    7,
    5,
    0x80 | IN_EP,
    0x02,
    64,
    0,
    0, // bulk IN
];

/// String descriptor 0: the languages (English, US).
static LANGUAGES: [u8; 4] = [4, 3, 0x09, 0x04];

/// Each endpoint's configuration (UECFG0X: type and direction; UECFG1X:
/// size and one bank, ALLOC), as SET_CONFIGURATION sets them up, with
/// endpoint 0's first.
pub const ENDPOINT_CONFIG: [(u8, u8, u8); 4] = [
    (0, 0x00, 0x32),         // control, 64 bytes
    (NOTIFY_EP, 0xC1, 0x02), // interrupt IN, 8 bytes
    (OUT_EP, 0x80, 0x32),    // bulk OUT, 64 bytes
    (IN_EP, 0x81, 0x32),     // bulk IN, 64 bytes
];

/// Data for the IN data stage of a control transfer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Payload {
    /// Bytes as they are.
    Bytes(&'static [u8]),
    /// A string descriptor made from ASCII text (UTF-16LE).
    Ascii(&'static str),
    /// The line coding (7 bytes).
    LineCoding([u8; 7]),
    /// A two-byte status or a one-byte configuration value.
    Short([u8; 2], u8),
}

impl Payload {
    /// Its length in bytes.
    pub fn len(&self) -> usize {
        match self {
            Payload::Bytes(b) => b.len(),
            Payload::Ascii(s) => 2 + 2 * s.len(),
            Payload::LineCoding(_) => 7,
            Payload::Short(_, n) => usize::from(*n),
        }
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Its byte `i` (0 past the end).
    pub fn byte(&self, i: usize) -> u8 {
        match self {
            Payload::Bytes(b) => b.get(i).copied().unwrap_or(0),
            Payload::Ascii(s) => match i {
                0 => self.len().min(255) as u8,
                1 => 3,
                i if i % 2 == 0 => s.as_bytes().get(i / 2 - 1).copied().unwrap_or(0),
                _ => 0,
            },
            Payload::LineCoding(c) => c.get(i).copied().unwrap_or(0),
            Payload::Short(b, _) => b.get(i).copied().unwrap_or(0),
        }
    }
}

/// The answer to a setup packet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reply {
    /// Send the first `len` bytes of the payload (the request's length
    /// cuts it), then take the host's status packet.
    In(Payload, u16),
    /// No data stage: acknowledge with a zero-length packet.
    Ack,
    /// SET_ADDRESS: acknowledge, then enable the address once the
    /// acknowledgement has gone out.
    Address(u8),
    /// SET_CONFIGURATION 1: set up the serial port's endpoints, acknowledge.
    Configure,
    /// A data stage from the host follows (SET_LINE_CODING): pass it to
    /// [`Control::line_coding_out`], then acknowledge.
    ReceiveLineCoding,
    /// SET_FEATURE(ENDPOINT_HALT) (`true`) or CLEAR_FEATURE(ENDPOINT_HALT)
    /// (`false`) on this endpoint number of the configuration: halt it
    /// (every transaction on it stalls), or clear its halt and reset its
    /// data toggle to DATA0 (USB 2.0 section 9.4.5); then acknowledge.
    Halt(u8, bool),
    /// Not supported: stall endpoint 0 until the next setup packet.
    Stall,
}

/// The serial port's control state: configuration, line coding, DTR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Control {
    configured: bool,
    line_coding: [u8; 7],
    dtr: bool,
    /// The halted endpoints of the configuration, bit n for endpoint n.
    halted: u8,
}

impl Default for Control {
    fn default() -> Self {
        Control::new()
    }
}

/// Line coding until the host sets one: 9600 baud, 8N1.
const DEFAULT_LINE_CODING: [u8; 7] = [0x80, 0x25, 0, 0, 0, 0, 8];

impl Control {
    /// After power-up or a bus reset: unconfigured, 9600 8N1, DTR low.
    pub const fn new() -> Control {
        Control {
            configured: false,
            line_coding: DEFAULT_LINE_CODING,
            dtr: false,
            halted: 0,
        }
    }

    /// The number of the endpoint at `address` (wIndex of a request to an
    /// endpoint: number and direction bit): endpoint 0 either way, the
    /// configuration's three endpoints once configured, `None` otherwise
    /// (a request error, USB 2.0 section 9.4).
    fn endpoint(&self, address: u8) -> Option<u8> {
        let number = address & 0x0F;
        let valid = match address {
            0x00 | 0x80 => true,
            a if a == 0x80 | NOTIFY_EP || a == OUT_EP || a == 0x80 | IN_EP => self.configured,
            _ => false,
        };
        valid.then_some(number)
    }

    /// The answer to a setup packet (standard requests of a device, the
    /// CDC-ACM class requests of interface 0); `serial` is the serial
    /// number string.
    pub fn setup(&mut self, packet: &[u8; 8], serial: &'static str) -> Reply {
        let [kind, request, v0, v1, i0, _, l0, l1] = *packet;
        let (value, length) = (u16::from_le_bytes([v0, v1]), u16::from_le_bytes([l0, l1]));
        let n = |p: Payload| Reply::In(p, length.min(p.len() as u16));
        match (kind, request) {
            // Standard, device.
            (0x80, 0x06) => match v1 {
                1 => n(Payload::Bytes(&DEVICE_DESCRIPTOR)),
                2 if v0 == 0 => n(Payload::Bytes(&CONFIG_DESCRIPTOR)),
                3 => match v0 {
                    0 => n(Payload::Bytes(&LANGUAGES)),
                    1 => n(Payload::Ascii(MANUFACTURER)),
                    2 => n(Payload::Ascii(PRODUCT)),
                    3 => n(Payload::Ascii(serial)),
                    _ => Reply::Stall,
                },
                _ => Reply::Stall,
            },
            (0x00, 0x05) => Reply::Address(v0 & 0x7F),
            // SET_CONFIGURATION clears every halt (USB 2.0 section 9.4.7).
            (0x00, 0x09) => match value {
                0 => {
                    self.configured = false;
                    self.dtr = false;
                    self.halted = 0;
                    Reply::Ack
                }
                1 => {
                    self.configured = true;
                    self.halted = 0;
                    Reply::Configure
                }
                _ => Reply::Stall,
            },
            (0x80, 0x08) => n(Payload::Short([u8::from(self.configured), 0], 1)),
            // GET_STATUS: the device (bus powered, no remote wake-up), an
            // interface (nothing), an endpoint (its halt bit).
            (0x80, 0x00) => n(Payload::Short([0, 0], 2)),
            (0x81, 0x00) if i0 < 2 => n(Payload::Short([0, 0], 2)),
            (0x82, 0x00) => match self.endpoint(i0) {
                Some(e) => n(Payload::Short([(self.halted >> e) & 1, 0], 2)),
                None => Reply::Stall,
            },
            // CLEAR_FEATURE / SET_FEATURE: ENDPOINT_HALT (feature 0) on an
            // endpoint of the configuration; endpoint 0 has no halt (USB 2.0
            // section 9.4.5 neither requires nor recommends one): accepted,
            // no effect. The device's features stall: it has no remote
            // wake-up (the configuration says so) and a full-speed device no
            // test mode; interfaces have none.
            (0x02, 0x01 | 0x03) if value == 0 => match self.endpoint(i0) {
                Some(0) => Reply::Ack,
                Some(e) => {
                    let halt = request == 0x03;
                    if halt {
                        self.halted |= 1 << e;
                    } else {
                        self.halted &= !(1 << e);
                    }
                    Reply::Halt(e, halt)
                }
                None => Reply::Stall,
            },
            (0x81, 0x0A) => n(Payload::Short([0, 0], 1)),
            (0x01, 0x0B) => Reply::Ack,
            // CDC class, interface 0.
            (0x21, 0x20) if i0 == 0 && length == 7 => Reply::ReceiveLineCoding,
            (0xA1, 0x21) if i0 == 0 => n(Payload::LineCoding(self.line_coding)),
            (0x21, 0x22) if i0 == 0 => {
                self.dtr = value & 1 != 0;
                Reply::Ack
            }
            (0x21, 0x23) if i0 == 0 => Reply::Ack, // SEND_BREAK
            _ => Reply::Stall,
        }
    }

    /// The SET_LINE_CODING data stage: 7 bytes (baud LE, stop bits,
    /// parity, data bits); anything else is ignored.
    pub fn line_coding_out(&mut self, data: &[u8]) {
        if let Ok(coding) = <[u8; 7]>::try_from(data) {
            self.line_coding = coding;
        }
    }

    /// Whether the host set configuration 1.
    pub fn configured(&self) -> bool {
        self.configured
    }

    /// The line coding's baud rate.
    pub fn baud(&self) -> u32 {
        let c = self.line_coding;
        u32::from_le_bytes([c[0], c[1], c[2], c[3]])
    }

    /// Whether the host holds the port open (DTR).
    pub fn dtr(&self) -> bool {
        self.dtr
    }

    /// Whether the host has halted endpoint `number` (SET_FEATURE).
    pub fn halted(&self, number: u8) -> bool {
        (self.halted >> (number & 7)) & 1 != 0
    }
}

/// Log frames waiting for the bulk IN endpoint: a ring of `N` bytes.
#[derive(Clone, Debug)]
pub struct LogQueue<const N: usize> {
    bytes: [u8; N],
    start: usize,
    len: usize,
    /// The last packet sent was a full one: the data ends with a
    /// zero-length packet when nothing follows.
    last_full: bool,
}

impl<const N: usize> Default for LogQueue<N> {
    fn default() -> Self {
        LogQueue::new()
    }
}

impl<const N: usize> LogQueue<N> {
    /// An empty queue.
    pub const fn new() -> LogQueue<N> {
        LogQueue {
            bytes: [0; N],
            start: 0,
            len: 0,
            last_full: false,
        }
    }

    /// Queues a whole frame, or drops it when it does not fit in the room
    /// left (its tick is then missing from what the host records, which
    /// `host replay` counts). Returns whether it was queued.
    pub fn push(&mut self, frame: &[u8]) -> bool {
        if frame.len() > N - self.len {
            return false;
        }
        for &b in frame {
            let at = (self.start + self.len) % N;
            self.bytes[at] = b;
            self.len += 1;
        }
        true
    }

    /// The next packet to send, at most `max` bytes (one contiguous piece
    /// of the ring): `Some(&[])` is a zero-length packet that ends data
    /// whose last packet was full, `None` means nothing to send.
    pub fn packet(&self, max: usize) -> Option<&[u8]> {
        if self.len == 0 {
            return self.last_full.then_some(&[]);
        }
        let end = (self.start + self.len.min(max)).min(N);
        self.bytes.get(self.start..end)
    }

    /// Takes `n` bytes off the front after they were written as a packet
    /// of an endpoint whose packets hold `max` bytes.
    pub fn sent(&mut self, n: usize, max: usize) {
        let n = n.min(self.len);
        self.start = (self.start + n) % N;
        self.len -= n;
        self.last_full = n == max;
    }

    /// Empties the queue (the host closed the port or the cable was pulled).
    pub fn clear(&mut self) {
        self.start = 0;
        self.len = 0;
        self.last_full = false;
    }

    /// Bytes waiting.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing waits.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// What a change of the line coding or DTR did to the touch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TouchChange {
    /// Nothing.
    None,
    /// 1200 baud and DTR low: stop the motors, store the bootloader key,
    /// let the watchdog reset the chip.
    Armed,
    /// DTR rose or the baud rate changed before the watchdog fired: clear
    /// the key, carry on.
    Cancelled,
}

/// The 1200-baud touch, from the port's line coding and DTR.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Touch {
    armed: bool,
}

impl Touch {
    /// Records the port's state (`configured`: the host has set the
    /// configuration; a reset or unplugging clears it); returns what changed.
    pub fn update(&mut self, configured: bool, baud: u32, dtr: bool) -> TouchChange {
        let armed = Touch::arms(configured, baud, dtr);
        let change = match (self.armed, armed) {
            (false, true) => TouchChange::Armed,
            (true, false) => TouchChange::Cancelled,
            _ => TouchChange::None,
        };
        self.armed = armed;
        change
    }

    /// Whether a reset into the bootloader is pending.
    pub fn armed(&self) -> bool {
        self.armed
    }

    /// Whether the port's state arms the touch: configured, 1200 baud,
    /// DTR low.
    pub fn arms(configured: bool, baud: u32, dtr: bool) -> bool {
        configured && baud == TOUCH_BAUD && !dtr
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::String;
    use std::vec::Vec;

    fn request(kind: u8, request: u8, value: u16, index: u16, length: u16) -> [u8; 8] {
        let (v, i, l) = (
            value.to_le_bytes(),
            index.to_le_bytes(),
            length.to_le_bytes(),
        );
        [kind, request, v[0], v[1], i[0], i[1], l[0], l[1]]
    }

    fn bytes(p: Payload, len: u16) -> Vec<u8> {
        (0..usize::from(len)).map(|i| p.byte(i)).collect()
    }

    #[test]
    fn descriptors_are_answered_cut_to_the_length_asked_for() {
        let mut c = Control::new();
        let Reply::In(p, len) = c.setup(&request(0x80, 6, 0x0100, 0, 64), "robot-003") else {
            panic!("device descriptor not sent");
        };
        // USB 2.0 table 9-8, written out: bcdUSB 2.00, class EF/02/01 (an
        // interface association), 64-byte endpoint 0, 1FFB:2300, bcdDevice
        // 1.00, strings 1, 2, 3, one configuration.
        assert_eq!(
            bytes(p, len),
            [
                18, 1, 0x00, 0x02, 0xEF, 0x02, 0x01, 64, 0xFB, 0x1F, 0x00, 0x23, 0x00, 0x01, 1, 2,
                3, 1
            ]
        );
        let Reply::In(p, len) = c.setup(&request(0x80, 6, 0x0200, 0, 9), "robot-003") else {
            panic!("configuration descriptor not sent");
        };
        // Its header only, as a host first asks: 75 bytes, 2 interfaces,
        // value 1, bus powered (0x80), 100 mA (50 x 2 mA).
        assert_eq!(bytes(p, len), [9, 2, 75, 0, 2, 1, 0, 0x80, 50]);
        let Reply::In(p, len) = c.setup(&request(0x80, 6, 0x0303, 0x0409, 255), "robot-003") else {
            panic!("serial number not sent");
        };
        let units: Vec<u16> = bytes(p, len)[2..]
            .chunks(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect();
        assert_eq!(String::from_utf16(&units).unwrap(), "robot-003");
        assert_eq!((p.byte(0), p.byte(1)), (20, 3));
        assert_eq!(c.setup(&request(0x80, 6, 0x0304, 0, 255), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x80, 6, 0x0600, 0, 10), ""), Reply::Stall);
    }

    #[test]
    fn the_configuration_descriptor_is_well_formed_and_its_endpoints_match_the_setup() {
        let d = &CONFIG_DESCRIPTOR;
        assert_eq!(usize::from(u16::from_le_bytes([d[2], d[3]])), d.len());
        let mut at = 0;
        let mut endpoints = Vec::new();
        while at < d.len() {
            let len = usize::from(d[at]);
            assert!(len >= 2 && at + len <= d.len(), "descriptor at {at}");
            if d[at + 1] == 5 {
                endpoints.push((d[at + 2], d[at + 3], d[at + 4]));
            }
            at += len;
        }
        assert_eq!(at, d.len());
        let configured: Vec<_> = ENDPOINT_CONFIG[1..]
            .iter()
            .map(|&(n, cfg0, cfg1)| {
                let dir = if cfg0 & 1 != 0 { 0x80 } else { 0 };
                (n | dir, cfg0 >> 6, 8u8 << (cfg1 >> 4))
            })
            .collect();
        assert_eq!(endpoints, configured);
    }

    #[test]
    fn endpoint_halts_are_set_cleared_and_reported_as_chapter_9_says() {
        let mut c = Control::new();
        let status = |c: &mut Control, ep: u16| match c.setup(&request(0x82, 0, 0, ep, 2), "") {
            Reply::In(p, len) => Some(bytes(p, len)),
            _ => None,
        };
        // Before SET_CONFIGURATION only endpoint 0 exists.
        assert_eq!(c.setup(&request(0x02, 3, 0, 0x83, 0), ""), Reply::Stall);
        assert_eq!(status(&mut c, 0x83), None);
        assert_eq!(status(&mut c, 0x80), Some(std::vec![0, 0]));
        c.setup(&request(0x00, 9, 1, 0, 0), "");
        assert_eq!(
            c.setup(&request(0x02, 3, 0, 0x83, 0), ""),
            Reply::Halt(3, true)
        );
        assert!(c.halted(3) && !c.halted(2));
        assert_eq!(status(&mut c, 0x83), Some(std::vec![1, 0]));
        assert_eq!(
            c.setup(&request(0x02, 3, 0, 0x02, 0), ""),
            Reply::Halt(2, true)
        );
        // CLEAR_FEATURE clears the halt (and the board resets the toggle),
        // also on an endpoint that was not halted.
        assert_eq!(
            c.setup(&request(0x02, 1, 0, 0x83, 0), ""),
            Reply::Halt(3, false)
        );
        assert_eq!(status(&mut c, 0x83), Some(std::vec![0, 0]));
        assert_eq!(
            c.setup(&request(0x02, 1, 0, 0x81, 0), ""),
            Reply::Halt(1, false)
        );
        // The wrong direction, an endpoint that does not exist, another feature.
        for ep in [0x03, 0x82, 0x01, 0x04, 0x84] {
            assert_eq!(
                c.setup(&request(0x02, 3, 0, ep, 0), ""),
                Reply::Stall,
                "{ep:#x}"
            );
        }
        assert_eq!(c.setup(&request(0x02, 3, 1, 0x83, 0), ""), Reply::Stall);
        // Endpoint 0 has no halt: accepted, no effect.
        assert_eq!(c.setup(&request(0x02, 3, 0, 0x80, 0), ""), Reply::Ack);
        assert_eq!(status(&mut c, 0x00), Some(std::vec![0, 0]));
        // No remote wake-up, no test mode, no interface features.
        assert_eq!(c.setup(&request(0x00, 3, 1, 0, 0), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x00, 1, 1, 0, 0), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x00, 3, 2, 0x0100, 0), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x01, 3, 0, 0, 0), ""), Reply::Stall);
        // SET_CONFIGURATION clears the halts.
        assert!(c.halted(2));
        c.setup(&request(0x00, 9, 1, 0, 0), "");
        assert!(!c.halted(2));
    }

    #[test]
    fn cdc_requests_set_the_line_coding_and_dtr_and_others_stall() {
        let mut c = Control::new();
        assert_eq!(c.baud(), 9600);
        assert_eq!(c.setup(&request(0x00, 5, 12, 0, 0), ""), Reply::Address(12));
        assert_eq!(c.setup(&request(0x00, 9, 1, 0, 0), ""), Reply::Configure);
        assert!(c.configured());
        assert_eq!(
            c.setup(&request(0x21, 0x20, 0, 0, 7), ""),
            Reply::ReceiveLineCoding
        );
        c.line_coding_out(&[0x00, 0xC2, 0x01, 0x00, 0, 0, 8]);
        assert_eq!(c.baud(), 115_200);
        c.line_coding_out(&[1, 2, 3]);
        assert_eq!(c.baud(), 115_200, "a short data stage is ignored");
        let Reply::In(p, len) = c.setup(&request(0xA1, 0x21, 0, 0, 7), "") else {
            panic!("line coding not sent");
        };
        assert_eq!(bytes(p, len), [0x00, 0xC2, 0x01, 0x00, 0, 0, 8]);
        assert_eq!(c.setup(&request(0x21, 0x22, 3, 0, 0), ""), Reply::Ack);
        assert!(c.dtr());
        assert_eq!(c.setup(&request(0x21, 0x22, 2, 0, 0), ""), Reply::Ack);
        assert!(!c.dtr());
        assert_eq!(c.setup(&request(0xA1, 0x7F, 0, 0, 4), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x21, 0x20, 0, 0, 3), ""), Reply::Stall);
        assert_eq!(c.setup(&request(0x00, 9, 0, 0, 0), ""), Reply::Ack);
        assert!(!c.configured());
    }

    #[test]
    fn any_setup_packet_gets_an_answer_without_panicking() {
        let mut c = Control::new();
        for kind in [0x00u8, 0x01, 0x02, 0x21, 0x80, 0x81, 0x82, 0xA1, 0xC0, 0x40] {
            for req in 0..=255u8 {
                for value in [
                    0u16, 1, 0x0100, 0x0200, 0x0201, 0x0300, 0x0303, 0x03FF, 0xFFFF,
                ] {
                    let reply = c.setup(&request(kind, req, value, 0, 255), "x");
                    if let Reply::In(p, len) = reply {
                        assert!(usize::from(len) <= p.len());
                    }
                }
            }
        }
    }
    #[test]
    fn frames_go_in_whole_or_are_dropped_whole() {
        let mut q = LogQueue::<128>::new();
        assert!(q.push(&[1; 71]));
        assert!(q.push(&[2; 50]));
        assert!(!q.push(&[3; 8]), "7 bytes left");
        assert_eq!(q.len(), 121);
        // A host reading again makes room for whole frames only.
        assert_eq!(q.packet(64), Some(&[1u8; 64][..]));
        q.sent(64, 64);
        assert!(q.push(&[3; 50]));
        assert!(!q.push(&[4; 71]));
    }

    #[test]
    fn packets_follow_the_ring_and_a_full_last_packet_is_followed_by_a_zero_length_one() {
        let mut q = LogQueue::<100>::new();
        let frame: Vec<u8> = (0..90).collect();
        assert!(q.push(&frame));
        let mut out = Vec::new();
        let mut zlp = 0;
        let round = |q: &mut LogQueue<100>, out: &mut Vec<u8>, zlp: &mut u32| {
            while let Some(p) = q.packet(64) {
                let p = p.to_vec();
                *zlp += u32::from(p.is_empty());
                out.extend_from_slice(&p);
                q.sent(p.len(), 64);
            }
        };
        round(&mut q, &mut out, &mut zlp);
        assert_eq!((out.as_slice(), zlp), (frame.as_slice(), 0));
        // 64 bytes that wrap round the ring's end: two packets, then nothing
        // more (the last one was short).
        let next: Vec<u8> = (100..164).collect();
        assert!(q.push(&next));
        out.clear();
        round(&mut q, &mut out, &mut zlp);
        assert_eq!(out, next);
        assert_eq!(zlp, 0);
        // Exactly one full packet: a zero-length packet ends it.
        let full = [7u8; 64];
        q.clear();
        assert!(q.push(&full));
        out.clear();
        round(&mut q, &mut out, &mut zlp);
        assert_eq!((out.len(), zlp), (64, 1));
        assert!(q.is_empty() && q.packet(64).is_none());
    }

    #[test]
    fn the_touch_arms_at_1200_baud_with_dtr_low_and_cancels_when_dtr_returns() {
        let mut t = Touch::default();
        // A terminal opens the port at 9600 and closes it: no touch.
        assert_eq!(t.update(true, 9600, true), TouchChange::None);
        assert_eq!(t.update(true, 9600, false), TouchChange::None);
        // Opened at 1200 (DTR high), then closed: armed.
        assert_eq!(t.update(true, 1200, true), TouchChange::None);
        assert_eq!(t.update(true, 1200, false), TouchChange::Armed);
        assert!(t.armed());
        assert_eq!(t.update(true, 1200, false), TouchChange::None);
        // DTR back in time: cancelled.
        assert_eq!(t.update(true, 1200, true), TouchChange::Cancelled);
        assert!(!t.armed());
        // Another baud rate cancels too, and so does a reset (unconfigured).
        t.update(true, 1200, false);
        assert_eq!(t.update(true, 115_200, false), TouchChange::Cancelled);
        t.update(true, 1200, false);
        assert_eq!(t.update(false, 1200, false), TouchChange::Cancelled);
    }
}
