//! The USB serial port's logic: what the board layer's driver for the
//! ATmega32U4's USB controller (`src/board/usb.rs`) and the control loop
//! decide without touching a register, tested on the host.
//!
//! - [`EndpointTable`]: the endpoints `usb-device` allocates (the control
//!   endpoint, then `usbd-serial`'s notification, bulk OUT and bulk IN
//!   endpoints, numbered 1, 2, 3), each one's UECFG0X/UECFG1X bytes, and
//!   the controller's limits: 7 endpoints, 832 bytes of endpoint memory,
//!   64 bytes per endpoint but endpoint 1 (256), one bank each.
//! - [`LogQueue`]: the log frames waiting for the bulk IN endpoint. A frame
//!   goes in whole or not at all (dropped, counted), so a host that stops
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

use usb_device::endpoint::{EndpointAddress, EndpointType};
use usb_device::{UsbDirection, UsbError};

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
pub const TOUCH_BAUD: u32 = 1200;
/// The bootloader enters itself after a watchdog reset when this word is
/// at SRAM [`BOOT_KEY_ADDR`] (`../shared/docs/hardware.md` section 6).
pub const BOOT_KEY: u16 = 0x7777;
/// Where the bootloader looks for [`BOOT_KEY`].
pub const BOOT_KEY_ADDR: u16 = 0x0800;

/// Endpoints of the ATmega32U4's USB controller.
pub const ENDPOINTS: usize = 7;
/// Largest packet of each endpoint.
const MAX_SIZE: [u16; ENDPOINTS] = [64, 256, 64, 64, 64, 64, 64];
/// The controller's endpoint memory (DPRAM), bytes.
const DPRAM: u16 = 832;

/// One endpoint's configuration, as the controller takes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EndpointConfig {
    /// Control, bulk, interrupt (isochronous is refused).
    pub kind: EndpointType,
    /// IN (device to host).
    pub is_in: bool,
    /// Packet size, 8..=256 bytes, a power of two.
    pub size: u16,
}

impl EndpointConfig {
    /// UECFG0X: EPTYPE (bits 7..6), EPDIR (bit 0).
    pub fn uecfg0x(&self) -> u8 {
        let kind = match self.kind {
            EndpointType::Control => 0b00,
            EndpointType::Isochronous { .. } => 0b01,
            EndpointType::Bulk => 0b10,
            EndpointType::Interrupt => 0b11,
        };
        kind << 6 | u8::from(self.is_in)
    }

    /// UECFG1X: EPSIZE (bits 6..4: 8 << EPSIZE bytes), one bank (EPBK
    /// 00), ALLOC (bit 1).
    pub fn uecfg1x(&self) -> u8 {
        let code = self.size.trailing_zeros() as u8 - 3;
        code << 4 | 1 << 1
    }

    /// Whether the endpoint is the control endpoint.
    pub fn is_control(&self) -> bool {
        self.kind == EndpointType::Control
    }
}

/// The endpoints allocated so far.
#[derive(Clone, Debug, Default)]
pub struct EndpointTable {
    endpoints: [Option<EndpointConfig>; ENDPOINTS],
    dpram_used: u16,
}

impl EndpointTable {
    /// An empty table.
    pub const fn new() -> EndpointTable {
        EndpointTable {
            endpoints: [None; ENDPOINTS],
            dpram_used: 0,
        }
    }

    /// Allocates an endpoint (`usb_device::bus::UsbBus::alloc_ep`): the
    /// address asked for, or the lowest free endpoint above 0 that can
    /// hold `max_packet` bytes. The control endpoint is allocated twice
    /// (OUT and IN) and configured once, as OUT.
    pub fn alloc(
        &mut self,
        dir: UsbDirection,
        addr: Option<EndpointAddress>,
        kind: EndpointType,
        max_packet: u16,
    ) -> Result<EndpointAddress, UsbError> {
        if matches!(kind, EndpointType::Isochronous { .. }) {
            return Err(UsbError::Unsupported);
        }
        let index = match addr {
            Some(a) if a.index() == 0 && kind == EndpointType::Control => {
                if self.endpoints[0].is_some() {
                    return Ok(a);
                }
                0
            }
            Some(a) => {
                let i = a.index();
                if i == 0 || i >= ENDPOINTS || self.endpoints[i].is_some() {
                    return Err(UsbError::InvalidEndpoint);
                }
                i
            }
            None => (1..ENDPOINTS)
                .find(|&i| self.endpoints[i].is_none() && max_packet <= MAX_SIZE[i])
                .ok_or(UsbError::EndpointOverflow)?,
        };
        let size = max_packet.max(8).next_power_of_two();
        if size > MAX_SIZE[index] {
            return Err(UsbError::EndpointMemoryOverflow);
        }
        if DPRAM - self.dpram_used < size {
            return Err(UsbError::EndpointMemoryOverflow);
        }
        self.dpram_used += size;
        self.endpoints[index] = Some(EndpointConfig {
            kind,
            // The control endpoint is configured as OUT; it answers both ways.
            is_in: dir == UsbDirection::In && kind != EndpointType::Control,
            size,
        });
        Ok(EndpointAddress::from_parts(index, dir))
    }

    /// The endpoint's configuration, if it was allocated.
    pub fn get(&self, index: usize) -> Option<EndpointConfig> {
        self.endpoints.get(index).copied().flatten()
    }

    /// The allocated endpoints in order, with their numbers.
    pub fn allocated(&self) -> impl Iterator<Item = (usize, EndpointConfig)> + '_ {
        self.endpoints
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.map(|e| (i, e)))
    }

    /// Endpoint memory in use, bytes.
    pub fn dpram_used(&self) -> u16 {
        self.dpram_used
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
    dropped: u16,
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
            dropped: 0,
        }
    }

    /// Queues a whole frame, or drops it (and counts it) when it does not
    /// fit in the room left. Returns whether it was queued.
    pub fn push(&mut self, frame: &[u8]) -> bool {
        if frame.len() > N - self.len {
            self.dropped = self.dropped.wrapping_add(1);
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

    /// Frames dropped because the host did not read them in time (wraps).
    pub fn dropped(&self) -> u16 {
        self.dropped
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
        let armed = configured && baud == TOUCH_BAUD && !dtr;
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
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn cdc_table() -> (EndpointTable, [EndpointAddress; 5]) {
        let mut t = EndpointTable::new();
        let ep0 = Some(EndpointAddress::from_parts(0, UsbDirection::Out));
        let ep0_in = Some(EndpointAddress::from_parts(0, UsbDirection::In));
        // The order usb-device and usbd-serial allocate in.
        let addrs = [
            t.alloc(UsbDirection::Out, ep0, EndpointType::Control, 64)
                .unwrap(),
            t.alloc(UsbDirection::In, ep0_in, EndpointType::Control, 64)
                .unwrap(),
            t.alloc(UsbDirection::In, None, EndpointType::Interrupt, 8)
                .unwrap(),
            t.alloc(UsbDirection::Out, None, EndpointType::Bulk, 64)
                .unwrap(),
            t.alloc(UsbDirection::In, None, EndpointType::Bulk, 64)
                .unwrap(),
        ];
        (t, addrs)
    }

    #[test]
    fn the_serial_ports_endpoints_are_numbered_0_to_3_with_the_controllers_config_bytes() {
        let (t, addrs) = cdc_table();
        let numbers: Vec<_> = addrs.iter().map(|a| (a.index(), a.is_in())).collect();
        assert_eq!(
            numbers,
            [(0, false), (0, true), (1, true), (2, false), (3, true)]
        );
        let cfg: Vec<_> = t
            .allocated()
            .map(|(i, c)| (i, c.uecfg0x(), c.uecfg1x()))
            .collect();
        // control OUT 64; interrupt IN 8; bulk OUT 64; bulk IN 64; ALLOC set, one bank.
        assert_eq!(
            cfg,
            [
                (0, 0x00, 0x32),
                (1, 0xC1, 0x02),
                (2, 0x80, 0x32),
                (3, 0x81, 0x32)
            ]
        );
        assert_eq!(t.dpram_used(), 64 + 8 + 64 + 64);
        assert!(t.get(0).unwrap().is_control() && t.get(4).is_none());
    }

    #[test]
    fn allocation_refuses_what_the_controller_cannot_do() {
        let mut t = EndpointTable::new();
        let at = |i| Some(EndpointAddress::from_parts(i, UsbDirection::In));
        assert_eq!(
            t.alloc(UsbDirection::In, at(2), EndpointType::Bulk, 128),
            Err(UsbError::EndpointMemoryOverflow)
        );
        assert!(t
            .alloc(UsbDirection::In, at(1), EndpointType::Bulk, 256)
            .is_ok());
        assert_eq!(
            t.alloc(UsbDirection::In, at(1), EndpointType::Bulk, 8),
            Err(UsbError::InvalidEndpoint)
        );
        assert_eq!(
            t.alloc(UsbDirection::In, at(7), EndpointType::Bulk, 8),
            Err(UsbError::InvalidEndpoint)
        );
        for _ in 2..ENDPOINTS {
            t.alloc(UsbDirection::Out, None, EndpointType::Bulk, 64)
                .unwrap();
        }
        assert_eq!(t.dpram_used(), 256 + 5 * 64);
        assert_eq!(
            t.alloc(UsbDirection::Out, None, EndpointType::Bulk, 8),
            Err(UsbError::EndpointOverflow)
        );
        let mut u = EndpointTable::new();
        for _ in 1..4 {
            u.alloc(UsbDirection::Out, None, EndpointType::Bulk, 64)
                .unwrap();
        }
        assert_eq!(
            u.alloc(
                UsbDirection::Out,
                None,
                EndpointType::Isochronous {
                    synchronization:
                        usb_device::endpoint::IsochronousSynchronizationType::NoSynchronization,
                    usage: usb_device::endpoint::IsochronousUsageType::Data,
                },
                64
            ),
            Err(UsbError::Unsupported)
        );
    }

    #[test]
    fn frames_go_in_whole_or_are_dropped_and_counted() {
        let mut q = LogQueue::<128>::new();
        assert!(q.push(&[1; 71]));
        assert!(q.push(&[2; 50]));
        assert!(!q.push(&[3; 8]), "7 bytes left");
        assert_eq!((q.len(), q.dropped()), (121, 1));
        // A host reading again makes room for whole frames only.
        assert_eq!(q.packet(64), Some(&[1u8; 64][..]));
        q.sent(64, 64);
        assert!(q.push(&[3; 50]));
        assert!(!q.push(&[4; 71]));
        assert_eq!(q.dropped(), 2);
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
