//! Keeping a helper thread awake for the length of a tick.
//!
//! A tick hands half of each of its passes to another thread of rayon's pool. Between passes
//! that thread has nothing to do and, after a few rounds of `sched_yield`, sleeps; the next pass
//! then waits for it to wake, which on a virtual machine takes tens of microseconds (about 60 µs
//! on the 2-core machine of `BENCHMARKS.md`: a sixth of a 1,000-agent tick, twice per tick).
//! [`with_helper`] keeps one thread looking for work, spinning, until the tick is over.

use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `f` on this thread while another thread of the current pool, if there is one, spins
/// looking for the work `f` hands out (rayon's `yield_now`) instead of sleeping; it stops when
/// `f` returns or panics. Which thread runs which part of a pass changes nothing in the results.
///
/// The spinning thread runs whatever job it finds in the pool, someone else's included: in a
/// pool shared with other work, `with_helper` returns once `f` and any such job are done. It
/// also takes a core for the whole of `f`, so it pays only where `f` hands out work often.
pub fn with_helper<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_num_threads() < 2 {
        return f();
    }
    let done = AtomicBool::new(false);
    let (r, ()) = rayon::join(
        || {
            // Set on the way out, panic included: the helper must not spin forever.
            let _done = Done(&done);
            f()
        },
        || {
            // Stolen first (a thread steals the oldest job, and this one is older than every
            // job `f` creates), so `f` never waits on this thread while this job is queued.
            while !done.load(Ordering::Acquire) {
                match rayon::yield_now() {
                    Some(rayon::Yield::Executed) => {}
                    Some(rayon::Yield::Idle) => std::hint::spin_loop(),
                    // Not on a pool thread: nothing to help with.
                    None => break,
                }
            }
        },
    );
    r
}

struct Done<'a>(&'a AtomicBool);

impl Drop for Done<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
    }

    #[test]
    fn returns_what_f_returns_and_runs_its_parallel_work() {
        for threads in [1, 2, 4] {
            let sum = pool(threads).install(|| {
                with_helper(|| (0..10_000u64).into_par_iter().map(|x| x * x).sum::<u64>())
            });
            assert_eq!(sum, (0..10_000u64).map(|x| x * x).sum::<u64>());
        }
    }

    #[test]
    fn the_helper_takes_part_of_the_work() {
        // With two threads, some items of a long pass run on the helper, not all on the caller.
        let seen = pool(2).install(|| {
            let caller = rayon::current_thread_index();
            with_helper(|| {
                (0..64usize)
                    .into_par_iter()
                    .with_max_len(1)
                    .map(|_| {
                        std::thread::sleep(std::time::Duration::from_millis(1));
                        rayon::current_thread_index() != caller
                    })
                    .filter(|&other| other)
                    .count()
            })
        });
        assert!(seen > 0, "the helper ran none of the 64 items");
    }

    #[test]
    fn a_panic_in_f_stops_the_helper_and_reaches_the_caller() {
        let r = pool(2).install(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                with_helper(|| -> u32 { panic!("in the tick") })
            }))
        });
        assert!(r.is_err());
    }

    #[test]
    fn outside_a_pool_it_still_runs_f() {
        assert_eq!(with_helper(|| 7), 7);
    }
}
