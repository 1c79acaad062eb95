//! Stopping a long run from outside: Ctrl-C in Python, a cancelled sweep.
//!
//! Whoever starts runs on a thread may put a [`Watch`] over them ([`Watch::over`]): a flag
//! that anyone may set (a sweep's calling thread sets it for its workers), and optionally a
//! poll that the runs' own thread calls (the Python binding's signal check, on the thread
//! that called in). A run counts its steps down and looks ([`look`]) when the count runs
//! out: the count adapts so that a run looks about every [`LOOK_EVERY`] of its work, so a
//! step costs one decrement, and a run stops within a fraction of a second of the flag,
//! whatever its step costs. A run that sees the flag ends with
//! [`GranrsError::Cancelled`](crate::GranrsError::Cancelled). Without a watch (the Rust API,
//! the tests), a run looks once and never again.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// About how often a watched run looks at its watch (and polls, if the watch has a poll).
pub const LOOK_EVERY: Duration = Duration::from_millis(20);

/// Steps a run takes before its first look.
pub(crate) const FIRST_LOOK: u32 = 64;

/// Most steps between two looks.
const MAX_STRIDE: u32 = 1 << 24;

/// What may stop the runs of one thread: a flag, and a poll asked at each look.
pub struct Watch<'a> {
    flag: &'a AtomicBool,
    poll: Option<&'a dyn Fn() -> bool>,
    /// Steps between looks, adapted to the steps' cost.
    stride: Cell<u32>,
    /// When the last look was.
    last: Cell<Instant>,
}

impl<'a> Watch<'a> {
    /// A watch on `flag`: the runs stop once it is set.
    pub fn new(flag: &'a AtomicBool) -> Self {
        Watch {
            flag,
            poll: None,
            stride: Cell::new(FIRST_LOOK),
            last: Cell::new(Instant::now()),
        }
    }

    /// A watch on `flag` that also asks `poll` at each look: true sets the flag.
    pub fn polling(flag: &'a AtomicBool, poll: &'a dyn Fn() -> bool) -> Self {
        Watch {
            poll: Some(poll),
            ..Watch::new(flag)
        }
    }

    /// Run `f` with this watch over every run it starts on this thread (the previous watch,
    /// if any, is back afterwards, also after a panic).
    pub fn over<R>(&self, f: impl FnOnce() -> R) -> R {
        struct Restore(*const ());
        impl Drop for Restore {
            fn drop(&mut self) {
                CURRENT.with(|c| c.set(self.0));
            }
        }
        let _restore = Restore(CURRENT.with(|c| c.replace(self as *const Watch<'a> as *const ())));
        f()
    }

    /// Whether the runs are to stop: the flag, or else the poll (which then sets it).
    fn stop(&self) -> bool {
        if self.flag.load(Ordering::Relaxed) {
            return true;
        }
        if self.poll.is_some_and(|poll| poll()) {
            self.flag.store(true, Ordering::Relaxed);
            return true;
        }
        false
    }
}

thread_local! {
    /// The watch over this thread's runs (a `*const Watch`), or null. Set only by
    /// [`Watch::over`], for the length of its call.
    static CURRENT: Cell<*const ()> = const { Cell::new(std::ptr::null()) };
}

/// A run's look at its thread's watch: whether to stop, and the steps until its next look.
#[cold]
#[inline(never)]
pub(crate) fn look() -> (bool, u32) {
    let current = CURRENT.with(Cell::get);
    if current.is_null() {
        return (false, u32::MAX);
    }
    // SAFETY: `CURRENT` is non-null only inside `Watch::over`, whose watch outlives the call
    // (it is borrowed for it), and this runs on the thread that set it, inside that call.
    let watch = unsafe { &*(current as *const Watch<'_>) };
    let now = Instant::now();
    let since = now.saturating_duration_since(watch.last.get());
    watch.last.set(now);
    let stride = watch.stride.get();
    let stride = if since < LOOK_EVERY / 2 {
        stride.saturating_mul(2).min(MAX_STRIDE)
    } else if since > LOOK_EVERY * 2 {
        (stride / 2).max(1)
    } else {
        stride
    };
    watch.stride.set(stride);
    (watch.stop(), stride)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_watch_a_run_looks_once() {
        assert_eq!(look(), (false, u32::MAX));
    }

    #[test]
    fn a_watch_sees_its_flag_and_its_poll_and_is_gone_after() {
        let flag = AtomicBool::new(false);
        Watch::new(&flag).over(|| {
            assert!(!look().0);
            flag.store(true, Ordering::Relaxed);
            assert!(look().0);
        });
        assert_eq!(look(), (false, u32::MAX));
        let flag = AtomicBool::new(false);
        let asked = Cell::new(0);
        let poll = || {
            asked.set(asked.get() + 1);
            asked.get() >= 2
        };
        Watch::polling(&flag, &poll).over(|| {
            assert!(!look().0);
            assert!(look().0);
        });
        assert!(flag.load(Ordering::Relaxed), "the poll sets the flag");
    }

    /// Quick steps widen the stride (fewer looks), slow ones narrow it.
    #[test]
    fn the_stride_follows_the_steps_cost() {
        let flag = AtomicBool::new(false);
        let watch = Watch::new(&flag);
        watch.over(|| {
            let (_, quick) = look();
            assert_eq!(quick, 2 * FIRST_LOOK);
            watch.last.set(Instant::now() - 3 * LOOK_EVERY);
            let (_, slow) = look();
            assert_eq!(slow, FIRST_LOOK);
        });
    }
}
