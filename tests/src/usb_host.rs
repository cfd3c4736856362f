//! A USB host for the firmware in simavr, written here from the USB 2.0
//! and CDC 1.1 specifications (not with the firmware's code).
//!
//! simavr's ATmega32U4 core has the USB controller model of its
//! `avr_usb.c` (endpoints 0..4, one 64-byte bank each): the host's side
//! is its ioctls, `usbs` (a setup packet), `usbr` (an IN transaction),
//! `usbw` (an OUT transaction) and `usbR` (a bus reset); an IN that the
//! firmware has not filled yet answers NAK (a bulk one answers an empty
//! packet instead), a stalled endpoint STALL. The model has no VBUS (its
//! `usbV` ioctl is declared but not handled), no start-of-frame and no
//! suspend: [`Zumo::plug_usb`] and [`Zumo::suspend_usb`] set the register
//! bits the silicon would (USBSTA.VBUS, UDINT.SUSPI, UDINT.WAKEUPI) in the
//! core's data memory. Nor does it filter by address (a packet reaches the
//! device whatever UDADDR holds: [`Zumo::usb_set_address`] reads UDADDR
//! itself), model data toggles, or lock the PLL only when it is set right
//! (any PLLE locks). Between tries of a NAKed transaction the host lets
//! the firmware run 20 us (a full-speed host retries within a frame). The
//! model does not NAK an OUT data stage while the setup packet before it
//! is unread (it overwrites it), so the host waits 5 ms before one.

use crate::zumo::{Zumo, CLOCK_HZ};
use simavr_ffi as ffi;
use std::ffi::c_void;

/// USBSTA (VBUS is bit 0) in data memory.
const USBSTA: usize = 0xD9;
/// UDINT (SUSPI bit 0, WAKEUPI bit 4) in data memory.
const UDINT: usize = 0xE1;
/// UDCON (DETACH is bit 0) in data memory.
const UDCON: usize = 0xE0;
/// UDADDR (UADD, ADDEN bit 7) in data memory.
const UDADDR: usize = 0xE3;
/// USBCON (FRZCLK is bit 5) in data memory.
const USBCON: usize = 0xD8;
/// PLLCSR (PLLE is bit 1) in data memory.
const PLLCSR: usize = 0x49;
/// How long a host waits after SET_ADDRESS before it uses the address
/// (Linux, `hub_port_init`); USB 2.0 gives the device 2 ms of it.
const SET_ADDRESS_SETTLE_US: u64 = 10_000;
const NAK: i32 = -2;
const STALL: i32 = -3;
/// How long the host waits between a setup packet and its OUT data stage.
const SETUP_TO_DATA_US: u64 = 5_000;
/// How long the host waits after a bus reset before its first setup packet.
const RESET_RECOVERY_US: u64 = 10_000;
/// How long a transaction may be NAKed before the host gives up.
const TIMEOUT_US: u64 = 50_000;

/// A control transfer the device refused (STALL).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stalled;

/// What [`Zumo::usb_enumerate`] read and measured.
#[derive(Clone, Debug)]
pub struct Enumeration {
    /// The device descriptor.
    pub device: Vec<u8>,
    /// The configuration descriptor, all of it.
    pub config: Vec<u8>,
    /// From SET_ADDRESS's status stage to the address enabled (UDADDR.ADDEN),
    /// in microseconds (the host looks every 10 us).
    pub address_us: u64,
}

/// A configuration descriptor split into its descriptors (each
/// `bLength` bytes); an error names the offset of one whose `bLength` is
/// under 2 or runs past the end, so a malformed descriptor fails a test
/// instead of looping it.
pub fn split_descriptors(bytes: &[u8]) -> Result<Vec<&[u8]>, String> {
    let mut out = Vec::new();
    let mut rest = bytes;
    while !rest.is_empty() {
        let len = usize::from(rest[0]);
        if len < 2 || len > rest.len() {
            return Err(format!(
                "descriptor at offset {}: bLength {len} with {} bytes left",
                bytes.len() - rest.len(),
                rest.len()
            ));
        }
        let (d, tail) = rest.split_at(len);
        out.push(d);
        rest = tail;
    }
    Ok(out)
}

/// A setup packet: bmRequestType, bRequest, wValue, wIndex, wLength.
pub fn setup(request_type: u8, request: u8, value: u16, index: u16, length: u16) -> [u8; 8] {
    let (v, i, l) = (
        value.to_le_bytes(),
        index.to_le_bytes(),
        length.to_le_bytes(),
    );
    [request_type, request, v[0], v[1], i[0], i[1], l[0], l[1]]
}

/// Calls one of the USB ioctls on endpoint `ep` with `buf` (`len` bytes
/// in, the count out).
fn ioctl(avr: *mut ffi::avr_t, code: [u8; 4], ep: u8, buf: &mut [u8], len: usize) -> (i32, usize) {
    let mut io = ffi::avr_io_usb {
        pipe: ep,
        sz: len as u32,
        buf: buf.as_mut_ptr(),
    };
    // SAFETY: the caller passes a live core; `buf` holds at least 64 bytes or `len`.
    let r = unsafe {
        ffi::avr_ioctl(
            avr,
            u32::from_be_bytes(code),
            &mut io as *mut _ as *mut c_void,
        )
    };
    (r, io.sz as usize)
}

/// A host that reads the bulk IN endpoint every 100 us and, every
/// `every` cycles, asks for the configuration descriptor, from a cycle
/// timer, while the test runs the firmware as it likes.
pub struct BackgroundHost {
    avr: *mut ffi::avr_t,
    ep: u8,
    every: u64,
    next_request: u64,
    stage: Stage,
    /// Bytes read from the bulk IN endpoint.
    bytes: Vec<u8>,
    /// Control transfers completed.
    requests: u32,
    setup_at: u64,
    /// The longest wait, in cycles, from a setup packet to the first
    /// packet of its answer.
    longest_wait: u64,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Stage {
    Idle,
    DataIn(usize),
    StatusOut,
}

/// Cycles between the background host's visits (100 us).
const VISIT: u64 = CLOCK_HZ / 10_000;

unsafe extern "C" fn visit(
    avr: *mut ffi::avr_t,
    when: ffi::avr_cycle_count_t,
    param: *mut c_void,
) -> u64 {
    // SAFETY: `param` is the boxed `BackgroundHost` of the `Zumo`, which
    // outlives the core's timers (field order).
    let h = unsafe { &mut *(param as *mut BackgroundHost) };
    let mut buf = [0u8; 64];
    let (r, n) = ioctl(avr, *b"usbr", h.ep, &mut buf, 64);
    if r == 0 {
        h.bytes.extend_from_slice(&buf[..n]);
    }
    h.stage = match h.stage {
        Stage::Idle if when >= h.next_request => {
            let mut packet = setup(0x80, 6, 0x0200, 0, 255).to_vec();
            packet.resize(64, 0);
            let (r, _) = ioctl(avr, *b"usbs", 0, &mut packet, 8);
            assert_eq!(r, 0, "setup packet refused");
            h.setup_at = when;
            Stage::DataIn(0)
        }
        Stage::DataIn(got) => match ioctl(avr, *b"usbr", 0, &mut buf, 64) {
            (0, n) => {
                if got == 0 {
                    h.longest_wait = h.longest_wait.max(when - h.setup_at);
                }
                if n < 64 {
                    Stage::StatusOut
                } else {
                    Stage::DataIn(got + n)
                }
            }
            (NAK, _) => Stage::DataIn(got),
            (r, _) => panic!("background GET_DESCRIPTOR: simavr error {r}"),
        },
        Stage::StatusOut => match ioctl(avr, *b"usbw", 0, &mut buf, 0) {
            (0, _) => {
                h.requests += 1;
                h.next_request = when + h.every;
                Stage::Idle
            }
            _ => Stage::StatusOut,
        },
        idle => idle,
    };
    when + VISIT
}

impl Zumo {
    /// From now on, a host in the background (a simavr cycle timer) reads
    /// the bulk IN endpoint `ep` every 100 us and asks for the
    /// configuration descriptor every `request_every_us`, however the test
    /// runs the firmware: the port is enumerated, open and streaming, with
    /// control transfers falling anywhere in the control period.
    pub fn stream_usb_in_background(&mut self, ep: u8, request_every_us: u64) {
        let every = request_every_us * (CLOCK_HZ / 1_000_000);
        let mut host = Box::new(BackgroundHost {
            avr: self.core(),
            ep,
            every,
            next_request: 0,
            stage: Stage::Idle,
            bytes: Vec::new(),
            requests: 0,
            setup_at: 0,
            longest_wait: 0,
        });
        let param = &mut *host as *mut BackgroundHost as *mut c_void;
        // SAFETY: the core is live; the host is boxed in `self`, dropped after the core.
        unsafe { ffi::avr_cycle_timer_register(host.avr, VISIT, Some(visit), param) };
        self.keep(host);
    }

    /// What the background host has read from the bulk IN endpoint, how
    /// many control transfers it completed, and the longest wait from a
    /// setup packet to its answer's first packet, in cycles (at the host's
    /// 100 us resolution).
    pub fn usb_background(&self) -> (&[u8], u32, u64) {
        self.kept::<BackgroundHost>().map_or((&[][..], 0, 0), |h| {
            (&h.bytes[..], h.requests, h.longest_wait)
        })
    }

    fn usb_ioctl(&mut self, code: [u8; 4], ep: u8, buf: &mut [u8], len: usize) -> (i32, usize) {
        ioctl(self.core(), code, ep, buf, len)
    }

    /// A host holding the port open: the cable plugged in (the device
    /// attaches within 100 ms), the device enumerated at `address`, line
    /// coding 115200 8N1, DTR set.
    pub fn usb_open(&mut self, address: u8) {
        self.plug_usb(true);
        for _ in 0..100 {
            if !self.usb_detached() {
                break;
            }
            self.run_ms(1);
        }
        assert!(!self.usb_detached(), "VBUS high for 100 ms: still detached");
        self.usb_enumerate(address);
        self.usb_set_line_coding(115_200)
            .expect("SET_LINE_CODING stalled");
        self.usb_set_dtr(true)
            .expect("SET_CONTROL_LINE_STATE stalled");
    }

    /// Plugs the cable in (VBUS high) or pulls it (VBUS low).
    pub fn plug_usb(&mut self, plugged: bool) {
        self.set_data_bit(USBSTA, 0, plugged);
    }

    /// The bus goes idle (UDINT.SUSPI), or the host wakes it (WAKEUPI).
    pub fn suspend_usb(&mut self, suspended: bool) {
        self.set_data_bit(UDINT, if suspended { 0 } else { 4 }, true);
    }

    fn set_data_bit(&mut self, addr: usize, bit: u8, on: bool) {
        // SAFETY: the core is live and `addr` is one of its I/O registers.
        unsafe {
            let p = (*self.core()).data.add(addr);
            *p = if on { *p | 1 << bit } else { *p & !(1 << bit) };
        }
    }

    /// Whether the firmware keeps the device detached (UDCON.DETACH).
    pub fn usb_detached(&self) -> bool {
        self.data(UDCON) & 1 != 0
    }

    /// Whether the firmware has frozen the USB controller's clock
    /// (USBCON.FRZCLK).
    pub fn usb_clock_frozen(&self) -> bool {
        self.data(USBCON) & 1 << 5 != 0
    }

    /// Whether the firmware has the USB PLL on (PLLCSR.PLLE).
    pub fn usb_pll_on(&self) -> bool {
        self.data(PLLCSR) & 1 << 1 != 0
    }

    /// The device address the firmware enabled (UDADDR with ADDEN), if any.
    pub fn usb_address(&self) -> Option<u8> {
        let a = self.data(UDADDR);
        (a & 0x80 != 0).then_some(a & 0x7F)
    }

    /// A bus reset, then the reset recovery time USB 2.0 gives a device
    /// before its first setup packet (10 ms, section 9.2.6.2). simavr's
    /// reset disables endpoint 0 until the firmware configures it again,
    /// which the firmware does when it next services the bus: within its
    /// longest gap between two services, not within 1 ms.
    pub fn usb_reset(&mut self) {
        let mut none = [0u8; 0];
        let (r, _) = self.usb_ioctl(*b"usbR", 0, &mut none, 0);
        assert_eq!(r, 0, "bus reset refused");
        self.run_us(RESET_RECOVERY_US);
    }

    /// One IN transaction on `ep`, retried while NAKed; an empty bulk
    /// answer counts as NAK unless `zlp_ok`.
    fn usb_in(&mut self, ep: u8, zlp_ok: bool) -> Result<Vec<u8>, Stalled> {
        self.usb_transaction(*b"usbr", ep, &[], zlp_ok)
    }

    /// One OUT transaction on `ep` (at most 64 bytes of `data`), retried
    /// while NAKed.
    pub fn usb_out(&mut self, ep: u8, data: &[u8]) -> Result<(), Stalled> {
        self.usb_transaction(*b"usbw", ep, data, true).map(|_| ())
    }

    /// One transaction (`code`: `usbr` IN, `usbw` OUT of `data`) retried
    /// every 20 us while NAKed, for at most `TIMEOUT_US`.
    fn usb_transaction(
        &mut self,
        code: [u8; 4],
        ep: u8,
        data: &[u8],
        zlp_ok: bool,
    ) -> Result<Vec<u8>, Stalled> {
        let is_in = code == *b"usbr";
        let mut waited = 0;
        loop {
            let mut buf = data.to_vec();
            buf.resize(64, 0);
            let (r, n) = self.usb_ioctl(code, ep, &mut buf, if is_in { 64 } else { data.len() });
            match r {
                0 if !is_in || n > 0 || zlp_ok => return Ok(buf[..n.min(64)].to_vec()),
                0 | NAK => {}
                STALL => return Err(Stalled),
                r => panic!("transaction on endpoint {ep}: simavr error {r}"),
            }
            assert!(
                waited < TIMEOUT_US,
                "transaction on endpoint {ep} NAKed for {TIMEOUT_US} us"
            );
            self.run_us(20);
            waited += 20;
        }
    }

    /// A control transfer on endpoint 0: the setup stage, the data stage
    /// (IN: packets until a short one or wLength; OUT: `data` in 64-byte
    /// packets), the status stage. Returns the data read.
    pub fn usb_control(&mut self, request: [u8; 8], data: &[u8]) -> Result<Vec<u8>, Stalled> {
        let mut packet = request.to_vec();
        packet.resize(64, 0);
        let (r, _) = self.usb_ioctl(*b"usbs", 0, &mut packet, 8);
        assert_eq!(r, 0, "setup packet refused");
        let length = usize::from(u16::from_le_bytes([request[6], request[7]]));
        if request[0] & 0x80 != 0 {
            let mut got = Vec::new();
            while got.len() < length {
                let p = self.usb_in(0, true)?;
                got.extend_from_slice(&p);
                if p.len() < 64 {
                    break;
                }
            }
            self.usb_out(0, &[])?;
            Ok(got)
        } else {
            if !data.is_empty() {
                // The model would let the data stage overwrite a setup
                // packet the firmware has not read yet (the silicon NAKs
                // it): give the firmware longer than its longest gap
                // between two services first.
                self.run_us(SETUP_TO_DATA_US);
            }
            for chunk in data.chunks(64) {
                self.usb_out(0, chunk)?;
            }
            let status = self.usb_in(0, true)?;
            assert!(status.is_empty(), "a status stage with data: {status:?}");
            Ok(Vec::new())
        }
    }

    /// SET_ADDRESS `address`, then the host looks every 10 us for the
    /// address to be enabled, for as long as Linux waits before using it
    /// (10 ms; it panics after that). Returns the microseconds from the
    /// status stage to the address enabled (USB 2.0 section 9.2.6.3 allows
    /// 2 ms).
    pub fn usb_set_address(&mut self, address: u8) -> u64 {
        self.usb_control(setup(0x00, 5, u16::from(address), 0, 0), &[])
            .expect("SET_ADDRESS stalled");
        let mut waited = 0;
        while self.usb_address() != Some(address) {
            assert!(
                waited < SET_ADDRESS_SETTLE_US,
                "address {address} not enabled {SET_ADDRESS_SETTLE_US} us after SET_ADDRESS"
            );
            self.run_us(10);
            waited += 10;
        }
        waited
    }

    /// What a host does when the device appears: bus reset, the device
    /// descriptor, SET_ADDRESS `address` ([`Zumo::usb_set_address`]), the
    /// configuration descriptor (its 9-byte header, then all of it),
    /// SET_CONFIGURATION 1.
    pub fn usb_enumerate(&mut self, address: u8) -> Enumeration {
        self.usb_reset();
        let device = self
            .usb_control(setup(0x80, 6, 0x0100, 0, 64), &[])
            .expect("GET_DESCRIPTOR(device) stalled");
        let address_us = self.usb_set_address(address);
        let head = self
            .usb_control(setup(0x80, 6, 0x0200, 0, 9), &[])
            .expect("GET_DESCRIPTOR(configuration) stalled");
        let total = u16::from_le_bytes([head[2], head[3]]);
        let config = self
            .usb_control(setup(0x80, 6, 0x0200, 0, total), &[])
            .expect("GET_DESCRIPTOR(configuration) stalled");
        self.usb_control(setup(0x00, 9, 1, 0, 0), &[])
            .expect("SET_CONFIGURATION stalled");
        Enumeration {
            device,
            config,
            address_us,
        }
    }

    /// A string descriptor as sent (English, 0x0409).
    pub fn usb_string_descriptor(&mut self, index: u8) -> Vec<u8> {
        self.usb_control(setup(0x80, 6, 0x0300 | u16::from(index), 0x0409, 255), &[])
            .expect("GET_DESCRIPTOR(string) stalled")
    }

    /// A string descriptor, decoded (English, 0x0409).
    pub fn usb_string(&mut self, index: u8) -> String {
        let d = self.usb_string_descriptor(index);
        let units: Vec<u16> = d[2..]
            .chunks(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect();
        String::from_utf16_lossy(&units)
    }

    /// CDC SET_LINE_CODING on interface 0: `baud`, 8N1.
    pub fn usb_set_line_coding(&mut self, baud: u32) -> Result<(), Stalled> {
        let mut coding = baud.to_le_bytes().to_vec();
        coding.extend_from_slice(&[0, 0, 8]);
        self.usb_control(setup(0x21, 0x20, 0, 0, 7), &coding)
            .map(|_| ())
    }

    /// CDC GET_LINE_CODING on interface 0: (baud, stop bits, parity, data bits).
    pub fn usb_line_coding(&mut self) -> (u32, u8, u8, u8) {
        let d = self
            .usb_control(setup(0xA1, 0x21, 0, 0, 7), &[])
            .expect("GET_LINE_CODING stalled");
        (
            u32::from_le_bytes([d[0], d[1], d[2], d[3]]),
            d[4],
            d[5],
            d[6],
        )
    }

    /// CDC SET_CONTROL_LINE_STATE on interface 0 (DTR, RTS).
    pub fn usb_set_dtr(&mut self, dtr: bool) -> Result<(), Stalled> {
        self.usb_control(setup(0x21, 0x22, u16::from(dtr) | 2, 0, 0), &[])
            .map(|_| ())
    }

    /// One IN transaction on the bulk endpoint `ep`, not retried: the
    /// bytes sent (none when NAKed, which simavr's model gives as an empty
    /// packet), or [`Stalled`] when the endpoint is halted.
    pub fn usb_bulk_in(&mut self, ep: u8) -> Result<Vec<u8>, Stalled> {
        let mut buf = [0u8; 64];
        match self.usb_ioctl(*b"usbr", ep, &mut buf, 64) {
            (0, n) => Ok(buf[..n.min(64)].to_vec()),
            (NAK, _) => Ok(Vec::new()),
            (STALL, _) => Err(Stalled),
            (r, _) => panic!("bulk IN on endpoint {ep}: simavr error {r}"),
        }
    }

    /// Reads the bulk IN endpoint `ep` for `us` microseconds, as a host
    /// polling it every 100 us: every byte sent.
    pub fn usb_read_bulk(&mut self, ep: u8, us: u64) -> Vec<u8> {
        let mut out = Vec::new();
        let mut t = 0;
        while t < us {
            let mut buf = [0u8; 64];
            let (r, n) = self.usb_ioctl(*b"usbr", ep, &mut buf, 64);
            assert!(
                r == 0 || r == NAK,
                "bulk IN on endpoint {ep}: simavr error {r}"
            );
            out.extend_from_slice(&buf[..n]);
            self.run_us(100);
            t += 100;
        }
        out
    }

    /// A host streaming the log: reads the bulk IN endpoint `ep` for `us`
    /// microseconds and, every `request_every_us`, asks for the
    /// configuration descriptor (75 bytes, two packets) as a host's
    /// driver might mid-run, so that control transfers fall anywhere in
    /// the control period. Returns every byte read from `ep`.
    pub fn usb_stream(&mut self, ep: u8, us: u64, request_every_us: u64) -> Vec<u8> {
        let mut out = Vec::new();
        let mut t = 0;
        while t < us {
            let slice = request_every_us.min(us - t);
            out.extend(self.usb_read_bulk(ep, slice));
            t += slice;
            let start = self.cycle();
            let config = self
                .usb_control(setup(0x80, 6, 0x0200, 0, 255), &[])
                .expect("GET_DESCRIPTOR(configuration) stalled mid-run");
            assert_eq!(config.len(), usize::from(config[2]));
            t += (self.cycle() - start) / 16;
        }
        out
    }

    fn cycle(&self) -> u64 {
        // SAFETY: the core is live.
        unsafe { (*self.core()).cycle }
    }
}
