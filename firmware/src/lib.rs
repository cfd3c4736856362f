//! Platform-independent logic of the Zumo 32U4 firmware, unit-tested on the host.
#![no_std]
