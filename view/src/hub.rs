//! The viewers of one simulation: each gets the messages through a queue
//! of [`QUEUE`] messages; a viewer whose queue is full (it stopped reading,
//! or reads slower than the simulation publishes) is dropped, so no viewer
//! is buffered without limit and none slows the others.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::Mutex;
use tungstenite::Utf8Bytes;

/// Messages a viewer may have waiting.
pub const QUEUE: usize = 16;

/// The viewers.
#[derive(Default)]
pub struct Hub {
    viewers: Mutex<Vec<SyncSender<Utf8Bytes>>>,
}

impl Hub {
    /// A new viewer, `first` (at most [`QUEUE`] messages) waiting in its queue.
    pub fn subscribe(&self, first: &[Utf8Bytes]) -> Receiver<Utf8Bytes> {
        let (tx, rx) = sync_channel(QUEUE);
        for message in first.iter().take(QUEUE) {
            // a fresh queue has room for these
            let _ = tx.try_send(message.clone());
        }
        self.lock().push(tx);
        rx
    }

    /// Sends `message` to every viewer; drops those whose queue is full or
    /// who went away. Returns how many were dropped.
    pub fn publish(&self, message: &Utf8Bytes) -> usize {
        let mut viewers = self.lock();
        let before = viewers.len();
        viewers.retain(|tx| match tx.try_send(message.clone()) {
            Ok(()) => true,
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => false,
        });
        before - viewers.len()
    }

    /// Drops every viewer (their queues end once read).
    pub fn close(&self) {
        self.lock().clear();
    }

    /// Viewers connected.
    pub fn viewers(&self) -> usize {
        self.lock().len()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<SyncSender<Utf8Bytes>>> {
        // a viewer list is valid whatever a panicking holder did
        self.viewers
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_viewer_that_stops_reading_is_dropped_once_its_queue_is_full() {
        let hub = Hub::default();
        let reader = hub.subscribe(&["hello".into()]);
        let idle = hub.subscribe(&["hello".into()]);
        let mut dropped = 0;
        for k in 0..3 * QUEUE {
            dropped += hub.publish(&format!("frame {k}").into());
            while reader.try_recv().is_ok() {}
        }
        assert_eq!((dropped, hub.viewers()), (1, 1));
        // the idle one holds at most its queue, and then it ends
        assert_eq!(idle.try_iter().count(), QUEUE);
        assert!(idle.recv().is_err());
        drop(reader);
        hub.publish(&"last".into());
        assert_eq!(hub.viewers(), 0);
    }
}
