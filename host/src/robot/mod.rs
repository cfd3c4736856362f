//! Tools for real robots: record their serial log ([`monitor`]) into a
//! recorded-log file ([`log_file`]), check a recording against the policy
//! ([`replay`], with training coverage from [`visits`]) or play it on a
//! page ([`log_view`]), and build and flash the firmware ([`flash`]). `docs/robot-logs.md` describes the flow.

pub mod flash;
pub mod frame_splitter;
pub mod log_file;
pub mod log_view;
pub mod monitor;
pub mod replay;
pub mod visits;
