//! Running a tick's parallel passes on the calling thread alone.
//!
//! When the tick governor (`tick/governor.rs`) finds that one thread is faster (another process
//! holds a core), the tick runs inside [`alone`]: every parallel pass asks [`min_len`] for its
//! smallest piece and splits with [`join`], and inside [`alone`] neither splits, so the calling
//! thread does all the work and no other pool thread is woken. A pool of one thread of its own
//! would do the same work, but each tick would then wake that thread and be woken by it, and the
//! OS may place the woken thread on the busy core: beside a busy core, on the 2-core machine of
//! `BENCHMARKS.md`, that ran boids 1–2 % slower than a one-thread run. Which thread runs which
//! part of a pass never changes a result (every pass writes per-agent outputs).

use std::cell::Cell;

thread_local! {
    static ALONE: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with every pass of this module's helpers on this thread (restored on the way out,
/// panic included).
pub fn alone<R>(f: impl FnOnce() -> R) -> R {
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            ALONE.set(self.0);
        }
    }
    let _restore = Restore(ALONE.replace(true));
    f()
}

/// Whether this thread is inside [`alone`].
#[inline]
pub fn is_alone() -> bool {
    ALONE.get()
}

/// The smallest piece a parallel iterator may split into: `len`, or no split at all inside
/// [`alone`] (rayon's `with_min_len`).
#[inline]
pub fn min_len(len: usize) -> usize {
    if is_alone() {
        usize::MAX
    } else {
        len
    }
}

/// `rayon::join`, or `a` then `b` on this thread inside [`alone`] (a job pushed to the pool would
/// wake a sleeping thread to take it).
pub fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB + Send,
    RA: Send,
    RB: Send,
{
    if is_alone() {
        let ra = a();
        (ra, b())
    } else {
        rayon::join(a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::{Duration, Instant};

    fn pool() -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
    }

    /// How many threads ran 64 slow items of a pass split by [`min_len`].
    fn threads_of_items() -> usize {
        let mut items = vec![0usize; 64];
        items.par_iter_mut().with_min_len(min_len(1)).for_each(|t| {
            std::thread::sleep(Duration::from_micros(300));
            *t = rayon::current_thread_index().unwrap_or(usize::MAX);
        });
        items.sort_unstable();
        items.dedup();
        items.len()
    }

    /// How many threads ran the two halves of a [`join`]: the first waits (up to a tenth of a
    /// second) for the second to start, which another thread does when it may take it.
    fn threads_of_join() -> usize {
        let started = AtomicBool::new(false);
        let (a, b) = join(
            || {
                let t = Instant::now();
                while !started.load(Ordering::Acquire) && t.elapsed() < Duration::from_millis(100) {
                    std::thread::sleep(Duration::from_micros(50));
                }
                rayon::current_thread_index()
            },
            || {
                started.store(true, Ordering::Release);
                rayon::current_thread_index()
            },
        );
        if a == b {
            1
        } else {
            2
        }
    }

    #[test]
    fn alone_keeps_every_piece_on_the_calling_thread() {
        let pool = pool();
        assert_eq!(pool.install(|| alone(threads_of_items)), 1);
        assert_eq!(pool.install(|| alone(threads_of_join)), 1);
        // Outside, the other thread takes its share (else the checks above prove nothing);
        // several tries, as a loaded machine may keep it from waking in time.
        assert!((0..10).any(|_| pool.install(threads_of_items) == 2));
        assert!((0..10).any(|_| pool.install(threads_of_join) == 2));
        assert!(!pool.install(is_alone));
    }

    #[test]
    fn alone_is_restored_after_a_panic() {
        let r = std::panic::catch_unwind(|| alone(|| panic!("a bug")));
        assert!(r.is_err());
        assert!(!is_alone());
        alone(|| alone(|| ()));
        assert!(!is_alone());
    }
}
