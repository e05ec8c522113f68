//! Linear stability exactly at the documented limits: on q̈ = −ω²q every method is stable 1%
//! below its hω_max (reference/compositions.json, reference/splittings.json) and unstable 1%
//! above (less for the splittings whose first unstable window is narrower), where the run stops
//! with a typed divergence error rather than producing non-finite numbers: with the energy
//! check lifted and with it on.

use varmech::integrators::{integrate, Method, Options};
use varmech::scenes::HarmonicOscillator;
use varmech::Error;

const STEPS: usize = 200_000;

fn run(method: Method, h: f64) -> Result<f64, Error> {
    let sys = HarmonicOscillator::new(1.0).unwrap();
    // Linear stability, not accuracy: near its limit a method's energy error is many times the
    // energy (bounded, but failed), so the energy check is off.
    let options = Options {
        save_every: STEPS,
        max_energy_error: None,
        ..Options::new(h, STEPS)
    };
    match integrate(&sys, method, &[0.0], &[1.0], &options, || Ok(())) {
        Ok(traj) => {
            let k = traj.len() - 1;
            Ok(traj.q_at(k)[0].hypot(traj.p_at(k)[0]))
        }
        Err(failure) => {
            let partial = &failure.partial;
            assert!(
                partial.q.iter().chain(&partial.p).all(|x| x.is_finite()),
                "partial trajectory holds non-finite values"
            );
            Err(failure.error)
        }
    }
}

/// How far above its limit a method is probed for instability: 1%, except for the splittings
/// whose first unstable window, a resonance near hω = π, is narrower than that (the scan's
/// windows: blanes_moan6 3.14143–3.1420, blanes_moan4 3.1635–3.1685, aba1064 3.1461–3.1535,
/// aba864 3.1422–3.1735); past it they are stable again up to the next window.
fn margin(method: Method) -> f64 {
    match method {
        Method::BlanesMoan6 => 1e-4,
        Method::BlanesMoan4 | Method::Aba864 | Method::Aba1064 => 1e-3,
        _ => 1e-2,
    }
}

#[test]
fn every_method_is_stable_just_below_and_unstable_just_above_its_limit() {
    for method in Method::ALL {
        let info = method.info();
        if info.h_omega_max.is_infinite() {
            continue; // the midpoint rule: see the next test
        }
        if info.h_omega_max > 0.0 {
            let below = run(method, 0.99 * info.h_omega_max);
            // The invariant ellipse of a symplectic method near its limit is elongated (hence
            // the generous bound), but it is bounded for all time.
            assert!(
                matches!(below, Ok(r) if r < 1e3),
                "{} at 0.99·hω_max: {below:?}",
                info.name
            );
        }
        let h_above = if info.h_omega_max > 0.0 {
            (1.0 + margin(method)) * info.h_omega_max
        } else {
            0.1
        };
        match run(method, h_above) {
            Err(Error::Divergence { step, time, .. }) => {
                assert!(step > 1 && (time - (step - 1) as f64 * h_above).abs() < 1e-9 * time.max(1.0));
            }
            // In a narrow window the growth factor is barely above 1 (blanes_moan4's 1.0023,
            // blanes_moan6's 1.0004 a step): the orbit grows by 1e200 or 1e36 in STEPS steps, far
            // past any bounded ellipse, without overflowing.
            Ok(r) if margin(method) < 1e-2 && r > 1e30 => {}
            other => panic!("{} at hω = {h_above}: expected divergence, got {other:?}", info.name),
        }
    }
}

/// The same with the run's energy check on, as a run has it by default (every state saved): at
/// 0.99 of the limit the energy error is a bounded offset of many times the kinetic energy,
/// which the check lets run to the end; just above the limit the check stops the run, its
/// partial trajectory finite, naming h·ω_max.
#[test]
fn the_energy_check_lets_a_run_below_the_limit_end_and_stops_one_above_it() {
    const GUARDED: usize = 20_000;
    let sys = HarmonicOscillator::new(1.0).unwrap();
    for method in Method::ALL {
        let (name, limit) = (method.info().name, method.info().h_omega_max);
        if !(limit.is_finite() && limit > 0.0) {
            continue;
        }
        let run = |h: f64| integrate(&sys, method, &[0.0], &[1.0], &Options::new(h, GUARDED), || Ok(()));
        match run(0.99 * limit) {
            Ok(traj) => {
                // Bounded, though not small (symplectic Euler's offset reaches 49.5 times the
                // energy): the second half's largest error is the first half's.
                let largest = |ks: std::ops::Range<usize>| {
                    ks.map(|k| (0.5 * (traj.q_at(k)[0].powi(2) + traj.p_at(k)[0].powi(2)) - 0.5).abs())
                        .fold(0.0_f64, f64::max)
                };
                let (first, second) = (largest(0..GUARDED / 2), largest(GUARDED / 2..GUARDED + 1));
                assert!(
                    traj.steps == GUARDED && second <= 1.01 * first,
                    "{name}: {first} then {second}"
                );
            }
            Err(failure) => panic!("{name} at 0.99·hω_max: {:?}", failure.error),
        }
        match run((1.0 + margin(method)) * limit) {
            Err(failure) => {
                let partial = &failure.partial;
                assert!(partial.q.iter().chain(&partial.p).all(|x| x.is_finite()), "{name}");
                match failure.error {
                    Error::Divergence { reason, .. } => assert!(
                        reason.contains(&format!("is beyond {name}'s stability limit")),
                        "{name}: {reason}"
                    ),
                    other => panic!("{name} above its limit: {other:?}"),
                }
            }
            Ok(_) => panic!("{name} above its limit ran to the end"),
        }
    }
}

#[test]
fn rk4_is_dissipative_below_its_limit() {
    // |R(iy)|² = 1 − y⁶/72 + y⁸/576 < 1 for 0 < y < 2√2: the amplitude decays by |R| a step.
    let (y, steps): (f64, usize) = (1.0, 1000);
    let r2 = 1.0 - y.powi(6) / 72.0 + y.powi(8) / 576.0;
    let sys = HarmonicOscillator::new(1.0).unwrap();
    let traj = integrate(
        &sys,
        Method::Rk4,
        &[0.0],
        &[1.0],
        &Options {
            max_energy_error: None,
            ..Options::new(y, steps)
        },
        || Ok(()),
    )
    .unwrap();
    let amplitude = traj.q_at(steps)[0].hypot(traj.p_at(steps)[0]);
    let expected = r2.powf(steps as f64 / 2.0);
    assert!(
        (amplitude / expected - 1.0).abs() < 1e-10,
        "{amplitude:e} vs {expected:e}"
    );
}

#[test]
fn the_midpoint_rule_turns_by_exactly_two_arctan_half_h_omega_at_any_step() {
    // On q̈ = −q the implicit midpoint map is a rotation by θ = 2 arctan(h/2) a step, so from
    // (0, 1) the state after n steps is (sin nθ, cos nθ): stable and without amplitude error at
    // every step size, with a phase error only.
    let sys = HarmonicOscillator::new(1.0).unwrap();
    for h in [0.1, 2.0, 50.0] {
        let steps = 1000;
        let traj = integrate(&sys, Method::Midpoint, &[0.0], &[1.0], &Options::new(h, steps), || {
            Ok(())
        })
        .unwrap();
        let theta = 2.0 * (0.5 * h).atan();
        for k in [1, 10, 1000] {
            let (s, c) = (k as f64 * theta).sin_cos();
            assert!(
                (traj.q_at(k)[0] - s).abs() < 1e-12 && (traj.p_at(k)[0] - c).abs() < 1e-12,
                "h = {h}, step {k}: ({}, {}) vs ({s}, {c})",
                traj.q_at(k)[0],
                traj.p_at(k)[0]
            );
        }
    }
}
