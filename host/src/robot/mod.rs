//! Tools for real robots: record their serial log ([`monitor`]) into a
//! recorded-log file ([`log_file`]), check a recording against the policy
//! ([`replay`], with training coverage from [`visits`]), and build and
//! flash the firmware ([`flash`]). `docs/robot-logs.md` describes the flow.

pub mod flash;
pub mod frame_splitter;
pub mod log_file;
pub mod monitor;
pub mod replay;
pub mod visits;
