//! The Zumo 32U4's pin map and bus addresses: the one place the board
//! layer (`src/board.rs`) and the simavr harness (`tests/src/zumo.rs`) read
//! them from. Pins are the ATmega32U4's port and bit as Pololu's Zumo 32U4
//! library drives them (motors in `Zumo32U4Motors`, the front sensor array
//! in `Zumo32U4LineSensors`, encoders in `Zumo32U4Encoders`, buttons and
//! LEDs in `Zumo32U4Buttons.h` and `Zumo32U4.h`); the Pixy's address is
//! its I2C default.

/// An I/O port of the ATmega32U4.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Port {
    /// PORTB.
    B,
    /// PORTC.
    C,
    /// PORTD.
    D,
    /// PORTE.
    E,
    /// PORTF.
    F,
}

impl Port {
    /// The port's letter (`b'B'` for PORTB), as simavr names its ports.
    pub const fn letter(self) -> u8 {
        match self {
            Port::B => b'B',
            Port::C => b'C',
            Port::D => b'D',
            Port::E => b'E',
            Port::F => b'F',
        }
    }
}

/// One pin: a port and a bit of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pin {
    /// The port.
    pub port: Port,
    /// The bit, 0..=7.
    pub bit: u8,
}

impl Pin {
    const fn new(port: Port, bit: u8) -> Pin {
        Pin { port, bit }
    }

    /// The pin's bit in its port's registers.
    pub const fn mask(self) -> u8 {
        1 << self.bit
    }
}

/// Red LED, low = on (PB0).
pub const LED_RED: Pin = Pin::new(Port::B, 0);
/// Right motor direction, high = reverse (PB1).
pub const DIR_RIGHT: Pin = Pin::new(Port::B, 1);
/// Left motor direction, high = reverse (PB2).
pub const DIR_LEFT: Pin = Pin::new(Port::B, 2);
/// Button A, active low with the pull-up on (PB3).
pub const BUTTON_A: Pin = Pin::new(Port::B, 3);
/// Right motor PWM, OC1A (PB5).
pub const PWM_RIGHT: Pin = Pin::new(Port::B, 5);
/// Left motor PWM, OC1B (PB6).
pub const PWM_LEFT: Pin = Pin::new(Port::B, 6);
/// The front array's IR emitters, LEDON, high = on (PB7).
pub const EMITTERS: Pin = Pin::new(Port::B, 7);
/// Yellow LED, high = on (PC7).
pub const LED_YELLOW: Pin = Pin::new(Port::C, 7);
/// Button B, active low, shared with the green LED (low = on) (PD5).
pub const BUTTON_B_LED_GREEN: Pin = Pin::new(Port::D, 5);
/// The field sensors, left, mid, right: the front array's DN1 (PF7), DN3
/// (PF4) and DN5 (PD6), read by RC discharge timing.
pub const FIELD_SENSORS: [Pin; 3] = [
    Pin::new(Port::F, 7),
    Pin::new(Port::F, 4),
    Pin::new(Port::D, 6),
];

/// Left encoder, A XOR B, pin-change interrupt PCINT4 (PB4).
pub const ENCODER_LEFT_XOR: Pin = Pin::new(Port::B, 4);
/// Left encoder, channel B (PE2).
pub const ENCODER_LEFT_B: Pin = Pin::new(Port::E, 2);
/// Right encoder, A XOR B, external interrupt INT6 (PE6).
pub const ENCODER_RIGHT_XOR: Pin = Pin::new(Port::E, 6);
/// Right encoder, channel B (PF0).
pub const ENCODER_RIGHT_B: Pin = Pin::new(Port::F, 0);
/// I2C clock, SCL (PD0): driven by hand only to free a stuck bus.
pub const I2C_SCL: Pin = Pin::new(Port::D, 0);
/// I2C data, SDA (PD1).
pub const I2C_SDA: Pin = Pin::new(Port::D, 1);

/// The Pixy's 7-bit I2C address.
pub const PIXY_ADDRESS: u8 = 0x54;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_sensors_sit_on_ports_f_and_d_and_no_two_pins_coincide() {
        let all = [
            LED_RED,
            DIR_RIGHT,
            DIR_LEFT,
            BUTTON_A,
            PWM_RIGHT,
            PWM_LEFT,
            EMITTERS,
            LED_YELLOW,
            BUTTON_B_LED_GREEN,
            FIELD_SENSORS[0],
            FIELD_SENSORS[1],
            FIELD_SENSORS[2],
            ENCODER_LEFT_XOR,
            ENCODER_LEFT_B,
            ENCODER_RIGHT_XOR,
            ENCODER_RIGHT_B,
            I2C_SCL,
            I2C_SDA,
        ];
        for (i, a) in all.iter().enumerate() {
            assert!(a.bit < 8);
            for b in &all[i + 1..] {
                assert_ne!(a, b);
            }
        }
        assert_eq!(FIELD_SENSORS.map(|p| p.port), [Port::F, Port::F, Port::D]);
        assert_eq!(FIELD_SENSORS[0].mask(), 0x80);
    }
}
