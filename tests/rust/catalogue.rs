//! The scene catalogue: every entry builds with its defaults, has a usable step and horizon, and
//! its invariants are the model's energy and momenta at t = 0.

use varmech::model::{hamiltonian, Generator, Lagrangian};
use varmech::scenes::{lookup, NonholonomicScene, Scene, SceneModel, Setup, CATALOGUE};
use varmech::Error;

/// Relative agreement of a catalogue value with the value computed from the initial state.
fn close(stated: f64, computed: f64) -> bool {
    (stated - computed).abs() <= 1e-8 * stated.abs().max(1.0)
}

/// The value of the invariant `name` at (q, p), computed from the model; None where the model
/// has no such quantity.
fn computed(model: &SceneModel, name: &str, q: &[f64], p: &[f64]) -> Option<f64> {
    let momentum = |symmetries: Vec<Generator>| {
        // The catalogue names cyclic momenta by their angle.
        let generator = match name {
            "p_phi" | "p_theta" => "p[1]",
            "p_psi" => "p[2]",
            other => other,
        };
        symmetries
            .into_iter()
            .find(|g| g.name() == generator)
            .map(|g| g.momentum(q, p))
    };
    let energy = matches!(name, "H" | "E");
    match model {
        SceneModel::Mechanical(Scene::FermiPastaUlam(s)) if name == "I" => {
            Some((1..=3).map(|j| s.oscillatory_energy(q, p, j)).sum())
        }
        SceneModel::Mechanical(Scene::EllipticBilliard(s)) if name == "L1L2" => Some(s.focal_product(q, p)),
        SceneModel::Mechanical(s) if energy => Some(hamiltonian(s, q, p).unwrap()),
        SceneModel::Mechanical(s) => momentum(varmech::model::MechanicalSystem::symmetries(s)),
        SceneModel::General(s) if energy => {
            assert!(!s.is_time_dependent() && !s.is_forced(), "{name}: no conserved energy");
            Some(s.energy(q, p, 0.0).unwrap())
        }
        SceneModel::General(s) => momentum(s.symmetries()),
        SceneModel::Constrained(s) if energy => Some(hamiltonian(&s.system, q, p).unwrap()),
        SceneModel::Constrained(s) => momentum(varmech::model::MechanicalSystem::symmetries(&s.system)),
        SceneModel::ConstrainedGeneral(s) if energy => Some(s.system.energy(q, p, 0.0).unwrap()),
        SceneModel::ConstrainedGeneral(_) => None,
        // The ball on the turntable's Jacobi integral J = E − Ω(x p_y − y p_x).
        SceneModel::Nonholonomic(NonholonomicScene::RollingSphere(s)) if name == "J" => {
            Some(s.system.jacobi_integral(s.constraints.rate(), q, p).unwrap())
        }
        SceneModel::Nonholonomic(s) if energy => Some(match s {
            NonholonomicScene::RollingDisk(s) => s.system.energy(q, p, 0.0).unwrap(),
            NonholonomicScene::ChaplyginSleigh(s) => s.system.energy(q, p, 0.0).unwrap(),
            NonholonomicScene::RollingSphere(s) => s.system.energy(q, p, 0.0).unwrap(),
        }),
        SceneModel::Nonholonomic(s) => momentum(s.symmetries()),
    }
}

fn check(setup: &Setup) {
    let name = setup.entry().name;
    let problem = setup.build().unwrap_or_else(|e| panic!("{name}: does not build: {e}"));
    let dt = setup.dt();
    assert!(dt.is_finite() && dt > 0.0, "{name}: dt = {dt}");
    assert!(
        problem.t_end.is_finite() && problem.t_end > 0.0,
        "{name}: t_end = {}",
        problem.t_end
    );
    assert!(!setup.description().is_empty(), "{name}: no description");
    let n = problem.system.dim();
    let (q, p) = (&problem.initial.q, &problem.initial.p);
    assert_eq!((q.len(), p.len()), (n, n), "{name}: initial state of the wrong size");
    for (invariant, stated) in setup.invariants() {
        let value = computed(&problem.system, invariant, q, p)
            .unwrap_or_else(|| panic!("{name}: invariant {invariant} is not computable"));
        assert!(
            close(stated, value),
            "{name}: {invariant} = {stated}, the model gives {value}"
        );
    }
}

#[test]
fn every_scene_builds_with_its_defaults() {
    for entry in &CATALOGUE {
        check(&entry.setup());
    }
}

#[test]
fn invariants_follow_the_parameters() {
    for (scene, parameter, value) in [
        ("kepler", "e", 0.3),
        ("kepler_polar", "e", 0.1),
        ("charged_particle", "B", 2.5),
        ("harmonic_oscillator", "omega", 3.0),
        ("bouncing_ball", "h0", 2.5),
        ("elliptic_billiard", "A", 3.0),
        ("elliptic_billiard", "px0", -0.2),
    ] {
        let mut setup = lookup(scene).unwrap().setup();
        setup.set(parameter, value).unwrap();
        assert_eq!(setup.get(parameter), Some(value));
        check(&setup);
    }
}

#[test]
fn names_are_unique_and_found() {
    for (i, entry) in CATALOGUE.iter().enumerate() {
        assert!(
            CATALOGUE[..i].iter().all(|e| e.name != entry.name),
            "{} twice",
            entry.name
        );
        assert_eq!(lookup(entry.name).unwrap().name, entry.name);
    }
}

#[test]
fn an_unknown_scene_is_a_typed_error_naming_the_known_ones() {
    match lookup("tippe_top") {
        Err(Error::InvalidArgument { argument, reason }) => {
            assert_eq!(argument, "name");
            assert!(reason.contains("tippe_top"), "{reason}");
            for entry in &CATALOGUE {
                assert!(reason.contains(entry.name), "{reason} does not name {}", entry.name);
            }
        }
        other => panic!("expected an invalid argument, got {other:?}"),
    }
}

#[test]
fn parameters_are_checked() {
    let mut kepler = lookup("kepler").unwrap().setup();
    assert!(matches!(
        kepler.set("omega", 1.0),
        Err(Error::InvalidArgument {
            argument: "parameter",
            ..
        })
    ));
    kepler.set("e", 1.5).unwrap();
    assert!(matches!(
        kepler.build(),
        Err(Error::InvalidArgument { argument: "e", .. })
    ));
    let mut chain = lookup("planar_chain").unwrap().setup();
    assert!(matches!(
        chain.set("links", 2.5),
        Err(Error::InvalidArgument { argument: "links", .. })
    ));
    chain.set("links", 3.0).unwrap();
    assert_eq!(chain.build().unwrap().system.dim(), 6);
    assert_eq!(chain.description(), "a planar chain of 3 rigid links");
}

#[test]
fn descriptions_follow_the_parameters() {
    let text = |name: &str| lookup(name).unwrap().setup().description();
    assert_eq!(text("kepler"), "Kepler orbit, eccentricity 0.6");
    assert_eq!(
        text("charged_particle"),
        "charged particle in the uniform field B = 1.0"
    );
    assert_eq!(
        text("damped_driven_pendulum"),
        "damped driven pendulum, γ = 0.5, A = 1.5, Ω = 0.666667"
    );
}
