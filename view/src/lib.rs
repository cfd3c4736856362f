//! The live view: a page on loopback (by default) that shows a simulation
//! running in this process, streamed to the browser over a WebSocket and
//! drawn on a canvas, with controls (play, pause, step, speed, reset with a
//! seed) and the run's settings (`docs/view.md`). `host view` serves it;
//! the Python environments' `render_mode="human"` can too.
//!
//! Modules, each on the ones below it: [`settings`] (the settings as URL
//! parameters and what a browser may name), [`session`] (a simulation as
//! the page sees it: hello and frames), [`hub`] (viewers' bounded queues),
//! [`http`] (the little HTTP the page needs), [`server`] (the stepping
//! thread, requests, WebSockets), [`recording`] (a robot's recorded log,
//! checked by the caller, on its own page).

pub mod http;
pub mod hub;
pub mod recording;
pub mod server;
pub mod session;
pub mod settings;

pub use recording::RecordingView;
pub use server::{Follower, Speed, View, ViewOptions};
pub use session::{Companion, Learning};
pub use settings::{Allowed, ViewController, ViewSettings};
