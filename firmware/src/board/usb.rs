//! The ATmega32U4's USB controller as a `usb-device` bus ([`Bus`]), and the
//! serial port on it ([`UsbPort`]): `usbd-serial`'s CDC-ACM class, the log
//! frames queued for its bulk IN endpoint and the 1200-baud touch
//! (`firmware::usb` holds the logic, this module the registers).
//!
//! Polled, never in an interrupt: the control loop calls
//! [`UsbPort::service`] while it waits (for the next period, a TWI step, a
//! USART byte, an EEPROM write), so the RC timing of the field sensors and
//! the encoder interrupts are never delayed by USB work, and no USB state
//! is shared with an interrupt. One service call, in order:
//!
//! 1. VBUS (USBSTA.VBUS): cable plugged in -> attach (UDCON.DETACH = 0);
//!    pulled -> detach, drop the queued frames, and do nothing more until
//!    it returns (the robot also runs on batteries alone);
//! 2. `UsbDevice::poll`: bus reset (UDINT.EORSTI), suspend and wake-up
//!    (SUSPI, WAKEUPI), setup packets and data on each endpoint (UEINTX);
//!    bytes the host sends to the port are read and ignored;
//! 3. the next packet of the log queue into the bulk IN endpoint, if the
//!    host holds the port open (DTR) and the endpoint's bank is free;
//! 4. the touch: 1200 baud with DTR low -> [`TouchChange::Armed`].
//!
//! Registers (data space addresses, ATmega32U4 datasheet section 22): each
//! flag is cleared by a read-modify-write that writes 0 to it, as LUFA
//! does; the endpoint registers apply to the endpoint UENUM selects.

use core::cell::Cell;
use core::ptr::{read_volatile, write_volatile};
use firmware::usb::{
    EndpointTable, LogQueue, Touch, TouchChange, MANUFACTURER, PACKET, PID, PRODUCT, VID,
};
use usb_device::bus::{PollResult, UsbBus, UsbBusAllocator};
use usb_device::device::{
    StringDescriptors, UsbDevice, UsbDeviceBuilder, UsbDeviceState, UsbVidPid,
};
use usb_device::endpoint::{EndpointAddress, EndpointType};
use usb_device::{UsbDirection, UsbError};
use usbd_serial::CdcAcmClass;

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
const RWAL: u8 = 1 << 5;
const RXSTPI: u8 = 1 << 3;
const RXOUTI: u8 = 1 << 2;
const TXINI: u8 = 1 << 0;
const STALLRQ: u8 = 1 << 5;
const STALLRQC: u8 = 1 << 4;
const EPEN: u8 = 1 << 0;

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

/// The USB controller: the endpoints allocated and which IN endpoints have
/// a packet in flight.
pub struct Bus {
    endpoints: EndpointTable,
    pending_in: Cell<u8>,
}

// SAFETY: the bus is used by the control loop only, never from an
// interrupt, and the ATmega32U4 has one core: nothing shares it.
unsafe impl Sync for Bus {}

impl Bus {
    fn select(&self, index: usize) -> Option<firmware::usb::EndpointConfig> {
        let config = self.endpoints.get(index)?;
        write(UENUM, index as u8);
        Some(config)
    }

    /// Configures every allocated endpoint (after a bus reset).
    fn configure(&self) {
        for (index, config) in self.endpoints.allocated() {
            write(UENUM, index as u8);
            write(UECONX, EPEN);
            write(UECFG0X, config.uecfg0x());
            write(UECFG1X, config.uecfg1x());
        }
    }
}

impl UsbBus for Bus {
    fn alloc_ep(
        &mut self,
        dir: UsbDirection,
        addr: Option<EndpointAddress>,
        kind: EndpointType,
        max_packet: u16,
        _interval: u8,
    ) -> usb_device::Result<EndpointAddress> {
        self.endpoints.alloc(dir, addr, kind, max_packet)
    }

    /// Pad regulator, controller and PLL on, VBUS pad on; attaching waits
    /// for VBUS ([`UsbPort::service`]).
    fn enable(&mut self) {
        write(UHWCON, UVREGE);
        write(USBCON, USBE | FRZCLK | OTGPADE);
        write(PLLCSR, PINDIV | PLLE);
        while read(PLLCSR) & PLOCK == 0 {}
        write(USBCON, USBE | OTGPADE);
        write(UDCON, DETACH);
    }

    fn reset(&self) {
        clear(UDINT, EORSTI | SUSPI | WAKEUPI);
        self.pending_in.set(0);
        self.configure();
    }

    fn set_device_address(&self, addr: u8) {
        // The address first, then ADDEN: never both in one write.
        write(UDADDR, addr & 0x7F);
        write(UDADDR, addr & 0x7F | ADDEN);
    }

    fn write(&self, ep: EndpointAddress, buf: &[u8]) -> usb_device::Result<usize> {
        let config = self.select(ep.index()).ok_or(UsbError::InvalidEndpoint)?;
        if usize::from(config.size) < buf.len() {
            return Err(UsbError::BufferOverflow);
        }
        if read(UEINTX) & TXINI == 0 {
            return Err(UsbError::WouldBlock);
        }
        if config.is_control() {
            for &b in buf {
                write(UEDATX, b);
            }
            clear(UEINTX, TXINI);
        } else {
            clear(UEINTX, TXINI);
            for &b in buf {
                write(UEDATX, b);
            }
            clear(UEINTX, FIFOCON);
        }
        self.pending_in.set(self.pending_in.get() | 1 << ep.index());
        Ok(buf.len())
    }

    fn read(&self, ep: EndpointAddress, buf: &mut [u8]) -> usb_device::Result<usize> {
        let config = self.select(ep.index()).ok_or(UsbError::InvalidEndpoint)?;
        let flags = read(UEINTX);
        if config.is_control() {
            if flags & (RXSTPI | RXOUTI) == 0 {
                return Err(UsbError::WouldBlock);
            }
            let n = usize::from(read(UEBCLX));
            let out = buf.get_mut(..n).ok_or(UsbError::BufferOverflow)?;
            for b in out.iter_mut() {
                *b = read(UEDATX);
            }
            clear(UEINTX, flags & (RXSTPI | RXOUTI));
            Ok(n)
        } else {
            if flags & RXOUTI == 0 {
                return Err(UsbError::WouldBlock);
            }
            clear(UEINTX, RXOUTI);
            let mut n = 0;
            for b in buf.iter_mut() {
                if read(UEINTX) & RWAL == 0 {
                    break;
                }
                *b = read(UEDATX);
                n += 1;
            }
            // A packet longer than `buf` is dropped whole.
            let overflow = read(UEINTX) & RWAL != 0;
            clear(UEINTX, FIFOCON);
            if overflow {
                Err(UsbError::BufferOverflow)
            } else {
                Ok(n)
            }
        }
    }

    fn set_stalled(&self, ep: EndpointAddress, stalled: bool) {
        if self.select(ep.index()).is_some() {
            write(UECONX, EPEN | if stalled { STALLRQ } else { STALLRQC });
        }
    }

    fn is_stalled(&self, ep: EndpointAddress) -> bool {
        self.select(ep.index()).is_some() && read(UECONX) & STALLRQ != 0
    }

    /// Freezes the controller's clock (it still sees the wake-up).
    fn suspend(&self) {
        clear(UDINT, SUSPI | WAKEUPI);
        write(USBCON, USBE | FRZCLK | OTGPADE);
    }

    fn resume(&self) {
        write(USBCON, USBE | OTGPADE);
        clear(UDINT, SUSPI | WAKEUPI);
    }

    fn poll(&self) -> PollResult {
        let events = read(UDINT);
        if events & EORSTI != 0 {
            return PollResult::Reset;
        }
        if events & WAKEUPI != 0 {
            return PollResult::Resume;
        }
        if events & SUSPI != 0 {
            return PollResult::Suspend;
        }
        if read(USBCON) & FRZCLK != 0 {
            return PollResult::None;
        }
        let (mut out, mut setup, mut done) = (0u16, 0u16, 0u16);
        let mut pending = self.pending_in.get();
        for (index, _) in self.endpoints.allocated() {
            write(UENUM, index as u8);
            let flags = read(UEINTX);
            let bit = 1u16 << index;
            if flags & RXOUTI != 0 {
                out |= bit;
            }
            if flags & RXSTPI != 0 {
                setup |= bit;
            }
            if pending & (1 << index) != 0 && flags & TXINI != 0 {
                done |= bit;
                pending &= !(1 << index);
            }
        }
        self.pending_in.set(pending);
        if out | setup | done == 0 {
            return PollResult::None;
        }
        PollResult::Data {
            ep_out: out,
            ep_in_complete: done,
            ep_setup: setup,
        }
    }
}

/// The bus allocator `usb-device` borrows for the program's lifetime.
static mut ALLOCATOR: Option<UsbBusAllocator<Bus>> = None;
/// The port, in static RAM (its control buffer and strings would
/// otherwise sit on the stack).
static mut PORT: Option<UsbPort> = None;

/// Bytes of log frames the port holds for the host: two frames of the
/// usual ~50 bytes, or one of the longest (71) and one more.
const QUEUE: usize = 128;

/// The serial port: the device, its CDC-ACM class, the log queue, the touch.
pub struct UsbPort {
    device: UsbDevice<'static, Bus>,
    class: CdcAcmClass<'static, Bus>,
    queue: LogQueue<QUEUE>,
    touch: Touch,
    vbus: bool,
    scratch: [u8; PACKET as usize],
}

impl UsbPort {
    /// Turns the controller on (detached until VBUS is seen) and builds
    /// the device: VID/PID, strings, a 64-byte control endpoint, one
    /// CDC-ACM function (with its interface association). Called once;
    /// `None` if called again or if the device cannot be built. Out of
    /// line: its temporaries stay out of the control loop's frame.
    #[inline(never)]
    pub fn take(serial: &'static str) -> Option<&'static mut UsbPort> {
        // SAFETY: the only references to ALLOCATOR and PORT ever made: they
        // are set here, once (a second call returns None before touching them).
        let (slot, port) = unsafe {
            (
                &mut *core::ptr::addr_of_mut!(ALLOCATOR),
                &mut *core::ptr::addr_of_mut!(PORT),
            )
        };
        if slot.is_some() {
            return None;
        }
        let alloc: &'static UsbBusAllocator<Bus> = slot.insert(UsbBusAllocator::new(Bus {
            endpoints: EndpointTable::new(),
            pending_in: Cell::new(0),
        }));
        let class = CdcAcmClass::new(alloc, PACKET);
        let strings = StringDescriptors::default()
            .manufacturer(MANUFACTURER)
            .product(PRODUCT)
            .serial_number(serial);
        let device = UsbDeviceBuilder::new(alloc, UsbVidPid(VID, PID))
            .composite_with_iads()
            .strings(&[strings])
            .ok()?
            .max_packet_size_0(PACKET as u8)
            .ok()?
            .build();
        Some(port.insert(UsbPort {
            device,
            class,
            queue: LogQueue::new(),
            touch: Touch::default(),
            vbus: false,
            scratch: [0; PACKET as usize],
        }))
    }

    /// One round of USB work (the module's step list); returns what
    /// happened to the touch.
    pub fn service(&mut self) -> TouchChange {
        let vbus = read(USBSTA) & VBUS != 0;
        if vbus != self.vbus {
            self.vbus = vbus;
            write(UDCON, if vbus { 0 } else { DETACH });
            self.queue.clear();
        }
        if vbus && self.device.poll(&mut [&mut self.class]) {
            // Bytes from the host: read and ignored.
            while self.class.read_packet(&mut self.scratch).is_ok() {}
        }
        let configured = vbus && self.device.state() == UsbDeviceState::Configured;
        let open = configured && self.class.dtr();
        if !open {
            self.queue.clear();
        } else if let Some(packet) = self.queue.packet(usize::from(PACKET)) {
            if let Ok(n) = self.class.write_packet(packet) {
                self.queue.sent(n, usize::from(PACKET));
            }
        }
        let baud = self.class.line_coding().data_rate();
        self.touch.update(configured, baud, self.class.dtr())
    }

    /// Queues a log frame for the host if it holds the port open (DTR):
    /// whole, or dropped when the host has not read the frames before it.
    pub fn send(&mut self, frame: &[u8]) {
        if self.vbus && self.device.state() == UsbDeviceState::Configured && self.class.dtr() {
            self.queue.push(frame);
        }
    }
}
