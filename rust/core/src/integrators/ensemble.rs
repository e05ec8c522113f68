//! Ensembles: many independent runs of [`integrate`], in parallel on a Rayon thread pool.
//!
//! Member i is [`integrate`] of its model from its row (q0ᵢ, p0ᵢ) with the shared [`Options`]:
//! one run on one thread, its state touched by no other, so its trajectory is bit for bit that
//! of the single run whatever the number of threads or the chunking. A member that fails keeps
//! its [`Failure`] (error and partial trajectory) and the others go on. Members may watch
//! native events, contacts and a schedule of impulses and samples ([`MemberWatch`]), each with
//! its own copy, as [`integrate_watching`] does.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::Relaxed};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

use super::{
    integrate_watching, Contacts, Counting, Detector, Dynamics, EventSpec, Failure, Generalized, Impulse, Method,
    NativeContact, NativeEvent, Options, Poll, Schedule, Trajectory, Watch,
};
use crate::{memory, Error, ModelError};

/// The members' models: one shared by all, or one each (a parameter sweep).
pub trait Members: Sync {
    /// The number of models: None for one model shared by every member.
    fn models(&self) -> Option<usize>;

    /// Runs `body` with member `member`'s model.
    fn with_model<R>(&self, member: usize, body: impl FnOnce(&dyn Dynamics) -> R) -> R;
}

/// One model for every member.
pub struct Shared<'a, S>(pub &'a S);

impl<S: Dynamics + Sync> Members for Shared<'_, S> {
    fn models(&self) -> Option<usize> {
        None
    }

    fn with_model<R>(&self, _member: usize, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        body(self.0)
    }
}

/// One model a member, in member order.
impl<S: Dynamics + Sync> Members for [S] {
    fn models(&self) -> Option<usize> {
        Some(self.len())
    }

    fn with_model<R>(&self, member: usize, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        body(&self[member])
    }
}

/// How an ensemble is spread over threads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parallel {
    /// The most threads to run members on; None: one a core.
    pub workers: Option<usize>,
    /// Members a task runs one after the other; None: 1 (Rayon's work stealing balances).
    pub chunk_size: Option<usize>,
}

impl Parallel {
    fn check(&self) -> Result<(), Error> {
        for (name, value) in [("workers", self.workers), ("chunk_size", self.chunk_size)] {
            if value == Some(0) {
                return Err(Error::invalid(name, "must be at least 1"));
            }
        }
        Ok(())
    }
}

/// The native events every member watches, with their specs: each member watches its own copy
/// of the functions (an event may keep state, such as the energy at the start of the run).
#[derive(Clone, Debug, Default)]
pub struct MemberEvents {
    pub functions: Vec<NativeEvent>,
    pub specs: Vec<EventSpec>,
}

impl MemberEvents {
    /// A member's detector.
    fn detector(&self) -> Result<Detector<'static>, Error> {
        Detector::new(Box::new(self.functions.clone()), self.specs.clone())
    }
}

/// What every member watches, native and owned, each member making its own copy: events,
/// contacts, and a schedule of impulses (their components as numbers) and samples (`t_eval`).
#[derive(Clone, Debug, Default)]
pub struct MemberWatch {
    pub events: MemberEvents,
    pub contacts: Vec<NativeContact>,
    pub impulses: Vec<(f64, Generalized)>,
    pub samples: Vec<f64>,
}

impl MemberWatch {
    /// A member's schedule, None without impulses and samples.
    fn schedule(&self) -> Option<Result<Schedule<'static>, Error>> {
        let impulses = self.impulses.iter().map(|(t, blow)| Impulse {
            t: *t,
            blow: Box::new(blow.clone()),
        });
        (!self.impulses.is_empty() || !self.samples.is_empty())
            .then(|| Schedule::new(impulses.collect(), self.samples.clone()))
    }

    /// Refuses what a member's run would refuse of these on n coordinates, before any starts.
    fn check(&self, n: usize) -> Result<(), Error> {
        self.events.detector()?;
        for (event, spec) in self.events.functions.iter().zip(&self.events.specs) {
            event.check(&spec.name, n)?;
        }
        Contacts::native(&self.contacts)?.fit(n)?;
        self.schedule().transpose()?.map_or(Ok(()), |s| s.fit(n))
    }
}

/// A member's run: its trajectory, or its failure with the states up to it.
pub type Outcome = Result<Trajectory, Box<Failure>>;

/// The members' outcomes in member order, and the poll's error if it stopped the ensemble
/// (the members then stopped, each with [`Error::Interrupted`] and its states so far; members
/// not yet started have none).
#[derive(Debug)]
pub struct Ensemble {
    pub members: Vec<Outcome>,
    pub interrupted: Option<ModelError>,
}

/// The source of a member's [`Error::Interrupted`] when the ensemble was stopped.
#[derive(Debug)]
pub struct Stopped;

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the ensemble was interrupted")
    }
}

impl std::error::Error for Stopped {}

/// How often the calling thread polls while the members run (the members themselves stop at
/// their next poll, 10–40 ms of run time apart).
const POLL: Duration = Duration::from_millis(10);

/// Integrates every member: member i is [`integrate_watching`] of `models`' member i from row
/// i of `q0` and `p0` (each members × n, row by row) with `options` and its own copy of
/// `watched` (events, the impacts on contacts, impulses and samples), run on at most
/// `parallel.workers` threads in tasks of `parallel.chunk_size` members; each member is bit for
/// bit its single run.
///
/// `poll` is called on the calling thread every 10 ms with the steps completed by all members
/// so far; an error from it stops every member at its next poll (within 40 ms of run time) with
/// [`Error::Interrupted`], keeping its states, and is returned in [`Ensemble::interrupted`].
///
/// Refuses (before any member starts) rows that are not whole, a `p0` of another size than
/// `q0`, models not one a member, `workers` or `chunk_size` of 0, invalid options, what a
/// member's run would refuse (naming `events`, `contacts`, `impulses` or `t_eval`), and an
/// ensemble whose saved states, twice over (the records and the stacked arrays made of them),
/// would not fit in the memory available (naming `save_every`).
#[allow(clippy::too_many_arguments)]
pub fn integrate_ensemble<M, P>(
    models: &M,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &Options,
    parallel: Parallel,
    watched: &MemberWatch,
    mut poll: P,
) -> Result<Ensemble, Error>
where
    M: Members + ?Sized,
    P: Poll,
{
    parallel.check()?;
    options.check()?;
    let count = models.models();
    if count == Some(0) {
        return Ok(Ensemble {
            members: Vec::new(),
            interrupted: None,
        });
    }
    let n = models.with_model(0, |sys| sys.dim());
    let members = q0.len().checked_div(n).unwrap_or(0);
    if n == 0 || !q0.len().is_multiple_of(n) {
        let reason = format!("has {} values, not whole rows of the model's n = {n}", q0.len());
        return Err(Error::invalid("q0", reason));
    }
    if p0.len() != q0.len() {
        let reason = format!("has {} rows of {n}, q0 has {members}", p0.len() as f64 / n as f64);
        return Err(Error::invalid("p0", reason));
    }
    if count.is_some_and(|c| c != members) {
        let reason = format!("{} models for {members} members", count.unwrap_or(0));
        return Err(Error::invalid("models", reason));
    }
    check_memory(members, n, options, watched.samples.len())?;
    watched.check(n)?;

    let workers = parallel
        .workers
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |w| w.get()))
        .min(members.max(1));
    let chunk = parallel.chunk_size.unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .build()
        .map_err(|e| Error::invalid("workers", format!("cannot start {workers} threads: {e}")))?;

    let (stop, steps) = (AtomicBool::new(false), AtomicUsize::new(0));
    let mut slots: Vec<Option<Outcome>> = (0..members).map(|_| None).collect();
    let mut interrupted = None;
    let (sender, receiver) = mpsc::channel::<()>();
    pool.in_place_scope(|scope| {
        for (c, slots) in slots.chunks_mut(chunk).enumerate() {
            let sender = sender.clone();
            let (stop, steps) = (&stop, &steps);
            scope.spawn(move |_| {
                for (k, slot) in slots.iter_mut().enumerate() {
                    let i = c * chunk + k;
                    let rows = i * n..(i + 1) * n;
                    let (q0, p0) = (&q0[rows.clone()], &p0[rows]);
                    *slot =
                        Some(models.with_model(i, |sys| member(sys, method, (q0, p0), options, watched, stop, steps)));
                    // The receiver waits until every member is done.
                    let _ = sender.send(());
                }
            });
        }
        drop(sender);
        let (mut finished, mut last) = (0, Instant::now());
        while finished < members {
            match receiver.recv_timeout(POLL) {
                Ok(()) => finished += 1,
                Err(RecvTimeoutError::Timeout) => {}
                // Every task ended (one panicked: the scope resumes its panic).
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if interrupted.is_none() && last.elapsed() >= POLL {
                last = Instant::now();
                if let Err(error) = poll.poll(steps.load(Relaxed)) {
                    stop.store(true, Relaxed);
                    interrupted = Some(error);
                }
            }
        }
    });
    let members = slots
        .into_iter()
        .map(|slot| slot.expect("every task filled its members"))
        .collect();
    Ok(Ensemble { members, interrupted })
}

/// One member: [`integrate_watching`] of its copy of `watched`, its poll counting its steps
/// into `steps` and stopping when `stop` is set; a member not started before the stop is
/// interrupted at its initial state.
fn member(
    sys: &dyn Dynamics,
    method: Method,
    (q0, p0): (&[f64], &[f64]),
    options: &Options,
    watched: &MemberWatch,
    stop: &AtomicBool,
    steps: &AtomicUsize,
) -> Outcome {
    let unstarted = |error| {
        let partial = Trajectory {
            dim: sys.dim(),
            ..Default::default()
        };
        Err(Box::new(Failure { error, partial }))
    };
    if stop.load(Relaxed) {
        return unstarted(Error::Interrupted {
            step: 0,
            time: options.t0,
            source: Box::new(Stopped),
        });
    }
    let mut counted = 0;
    let poll = Counting(|done: usize| {
        steps.fetch_add(done.saturating_sub(counted), Relaxed);
        counted = done;
        match stop.load(Relaxed) {
            true => Err(Box::new(Stopped) as ModelError),
            false => Ok(()),
        }
    });
    let events = &watched.events;
    let mut detector = match (!events.functions.is_empty()).then(|| events.detector()).transpose() {
        Ok(detector) => detector,
        Err(error) => return unstarted(error),
    };
    let (contacts, schedule) = match (Contacts::native(&watched.contacts), watched.schedule().transpose()) {
        (Ok(contacts), Ok(schedule)) => (contacts, schedule),
        (Err(error), _) | (_, Err(error)) => return unstarted(error),
    };
    let watch = Watch {
        events: detector.as_mut(),
        contacts: (!contacts.is_empty()).then_some(&contacts),
        schedule: schedule.as_ref(),
    };
    let outcome = integrate_watching(sys, method, q0, p0, options, poll, watch);
    steps.fetch_add(options.steps.saturating_sub(counted), Relaxed);
    outcome
}

/// Refuses an ensemble whose saved states would not fit in memory twice over (the members'
/// records, and the stacked arrays made of them), naming `save_every`, or `t_eval` where the
/// members keep the states at its `samples` times alone.
fn check_memory(members: usize, n: usize, options: &Options, samples: usize) -> Result<(), Error> {
    let (argument, saved, advice) = match samples {
        0 => (
            "save_every",
            (options.steps / options.save_every).saturating_add(2),
            "raise save_every",
        ),
        samples => ("t_eval", samples.saturating_add(2), "pass fewer t_eval times"),
    };
    let rows = members.saturating_mul(saved).saturating_mul(2);
    memory::check_bytes(rows, (2 * n + 3) * std::mem::size_of::<f64>()).map_err(|e| {
        let reason = format!(
            "{members} members × {saved} saved states of {n} coordinates: {e}; {advice} (or run fewer members at a \
             time)"
        );
        Error::invalid(argument, reason)
    })
}
