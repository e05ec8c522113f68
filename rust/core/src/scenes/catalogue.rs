//! The catalogue of native scenes: for each, its name, parameters with their defaults, a
//! description, a step that resolves it for a quick look, the values of its invariants at t = 0
//! and how to build it.

use std::f64::consts::PI;

use super::{
    cartesian_pendulum, cartesian_spherical_pendulum, planar_chain, BouncingBall, ChaplyginSleigh, ChargedParticle,
    DampedDrivenPendulum, DoublePendulum, EllipticBilliard, FermiPastaUlam, HarmonicOscillator, HeavyTop, HenonHeiles,
    Kepler, KeplerPolar, LagrangianScene, LinkedMasses, NBody, NonholonomicScene, Pendulum, Problem, RigidBody,
    RollingDisk, RollingSphere, Scene, SphericalPendulum,
};
use crate::integrators::{Dynamics, General};
use crate::model::{Constrained, Distances, Lagrangian, MechanicalSystem};
use crate::Error;

/// A native scene's model: a separable mechanical system, a general Lagrangian, either on
/// holonomic constraints, or a Lagrangian with velocity constraints.
#[derive(Clone, Debug)]
pub enum SceneModel {
    Mechanical(Scene),
    General(LagrangianScene),
    Constrained(LinkedMasses),
    /// A general Lagrangian on constraints (the rigid body in quaternions).
    ConstrainedGeneral(Constrained<RigidBody, Distances>),
    /// A Lagrangian with velocity constraints (rolling, a blade).
    Nonholonomic(NonholonomicScene),
}

impl SceneModel {
    /// Number of coordinates n.
    pub fn dim(&self) -> usize {
        match self {
            SceneModel::Mechanical(s) => MechanicalSystem::dim(s),
            SceneModel::General(s) => Lagrangian::dim(s),
            SceneModel::Constrained(s) => MechanicalSystem::dim(&s.system),
            SceneModel::ConstrainedGeneral(s) => Lagrangian::dim(&s.system),
            SceneModel::Nonholonomic(NonholonomicScene::RollingDisk(s)) => MechanicalSystem::dim(&s.system),
            SceneModel::Nonholonomic(NonholonomicScene::ChaplyginSleigh(s)) => MechanicalSystem::dim(&s.system),
            SceneModel::Nonholonomic(NonholonomicScene::RollingSphere(s)) => Lagrangian::dim(&s.system),
        }
    }

    /// Runs `body` with the scene as the core's [`Dynamics`]: a general Lagrangian wrapped in
    /// [`General`] for the variational methods.
    pub fn with_dynamics<R>(&self, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        match self {
            SceneModel::Mechanical(scene) => body(scene),
            SceneModel::General(scene) => body(&General(scene)),
            SceneModel::Constrained(scene) => body(scene),
            SceneModel::ConstrainedGeneral(scene) => body(&Constrained {
                system: General(&scene.system),
                constraints: scene.constraints.clone(),
            }),
            SceneModel::Nonholonomic(NonholonomicScene::RollingDisk(scene)) => body(scene),
            SceneModel::Nonholonomic(NonholonomicScene::ChaplyginSleigh(scene)) => body(scene),
            SceneModel::Nonholonomic(NonholonomicScene::RollingSphere(scene)) => body(scene),
        }
    }
}

/// A parameter of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameter {
    pub name: &'static str,
    pub default: f64,
    /// Whether it counts something (its values are whole numbers).
    pub integer: bool,
}

const fn real(name: &'static str, default: f64) -> Parameter {
    Parameter {
        name,
        default,
        integer: false,
    }
}

/// One scene of the catalogue. Its description, step, invariants and model depend on the
/// values of its parameters: set them on a [`Setup`].
pub struct CatalogueEntry {
    pub name: &'static str,
    pub parameters: &'static [Parameter],
    description: fn(&Setup) -> String,
    dt: fn(&Setup) -> f64,
    invariants: fn(&Setup) -> Vec<(&'static str, f64)>,
    build: fn(&Setup) -> Result<Problem<SceneModel>, Error>,
}

impl CatalogueEntry {
    /// The scene with its parameters at their defaults.
    pub fn setup(&'static self) -> Setup {
        Setup {
            entry: self,
            values: self.parameters.iter().map(|p| p.default).collect(),
        }
    }
}

impl std::fmt::Debug for CatalogueEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CatalogueEntry")
            .field("name", &self.name)
            .field("parameters", &self.parameters)
            .finish_non_exhaustive()
    }
}

/// A catalogue entry with a value for each of its parameters.
#[derive(Clone, Debug)]
pub struct Setup {
    entry: &'static CatalogueEntry,
    values: Vec<f64>,
}

impl Setup {
    /// The entry set up.
    pub fn entry(&self) -> &'static CatalogueEntry {
        self.entry
    }

    /// The value of the parameter `name`, if the scene has one.
    pub fn get(&self, name: &str) -> Option<f64> {
        let i = self.entry.parameters.iter().position(|p| p.name == name)?;
        Some(self.values[i])
    }

    /// Sets the parameter `name` to `value`; the scene checks the value's range when it is built.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), Error> {
        let parameters = self.entry.parameters;
        let Some(i) = parameters.iter().position(|p| p.name == name) else {
            let known: Vec<_> = parameters.iter().map(|p| p.name).collect();
            let known = if known.is_empty() {
                "it has none".to_string()
            } else {
                format!("its parameters are {}", known.join(", "))
            };
            let reason = format!("scene {} has no parameter {name:?}; {known}", self.entry.name);
            return Err(Error::invalid("parameter", reason));
        };
        if parameters[i].integer && !(value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64) {
            return Err(Error::invalid(
                parameters[i].name,
                format!("must be a whole number, got {value}"),
            ));
        }
        self.values[i] = value;
        Ok(())
    }

    /// What the scene shows.
    pub fn description(&self) -> String {
        (self.entry.description)(self)
    }

    /// A step that resolves the scene for a quick look.
    pub fn dt(&self) -> f64 {
        (self.entry.dt)(self)
    }

    /// The conserved quantities (by name) and their values at t = 0.
    pub fn invariants(&self) -> Vec<(&'static str, f64)> {
        (self.entry.invariants)(self)
    }

    /// The model with its initial state, horizon t_end and reference solution.
    pub fn build(&self) -> Result<Problem<SceneModel>, Error> {
        (self.entry.build)(self)
    }

    /// A declared parameter's value (the table reads only its own entry's parameters).
    fn value(&self, name: &str) -> f64 {
        self.get(name).expect("a parameter the entry declares")
    }
}

/// The scene called `name`.
pub fn lookup(name: &str) -> Result<&'static CatalogueEntry, Error> {
    CATALOGUE.iter().find(|e| e.name == name).ok_or_else(|| {
        let names: Vec<_> = CATALOGUE.iter().map(|e| e.name).collect();
        Error::invalid(
            "name",
            format!("unknown scene {name:?}; choose one of {}", names.join(", ")),
        )
    })
}

/// x as C's `%g` (and Python's `:g`) writes it: six significant digits, trailing zeros dropped.
fn general(x: f64) -> String {
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if !x.is_finite() {
        return x.to_string().to_lowercase();
    }
    let scientific = format!("{x:.5e}");
    let (mantissa, exponent) = scientific.split_once('e').expect("an exponent");
    let exponent: i32 = exponent.parse().expect("an integer exponent");
    if (-4..6).contains(&exponent) {
        let decimals = (5 - exponent).max(0) as usize;
        trim(format!("{x:.decimals$}"))
    } else {
        let sign = if exponent < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa.to_string()), exponent.abs())
    }
}

/// The fewest whole steps of at most `most` to `t_end` (so that a run to t_end at the scene's
/// step t_end/N ends there).
fn steps_to(t_end: f64, most: f64) -> u64 {
    (t_end / most).ceil() as u64
}

fn mechanical(s: Scene) -> SceneModel {
    SceneModel::Mechanical(s)
}

fn general_lagrangian(s: LagrangianScene) -> SceneModel {
    SceneModel::General(s)
}

const E: Parameter = real("e", 0.6);

fn nonholonomic(s: NonholonomicScene) -> SceneModel {
    SceneModel::Nonholonomic(s)
}

/// J = E − Ω(x v_y − y v_x) at t = 0 of the ball (I = 2a²/5) on the turntable, E = ½|v|² +
/// ½I|ω|² with aω = (Ωx − v_y, v_x + Ωy, aω_z) from the rolling.
fn turntable_jacobi(s: &Setup) -> f64 {
    let (omega, x, y, vx, vy) = (
        s.value("omega"),
        s.value("x0"),
        s.value("y0"),
        s.value("vx0"),
        s.value("vy0"),
    );
    let rolling = (omega * x - vy).powi(2) + (vx + omega * y).powi(2);
    let spin = 0.2 * (s.value("radius") * s.value("spin")).powi(2);
    0.5 * (vx * vx + vy * vy) + 0.2 * rolling + spin - omega * (x * vy - y * vx)
}

/// p_φ = Iω_z = (2/5)a²ω_z of a ball scene.
fn ball_spin(s: &Setup) -> f64 {
    0.4 * s.value("radius").powi(2) * s.value("spin")
}

/// Every native scene, in the order of the tour.
pub static CATALOGUE: [CatalogueEntry; 23] = [
    CatalogueEntry {
        name: "harmonic_oscillator",
        parameters: &[real("omega", 1.0)],
        description: |_| "the linear test equation q'' = -ω²q".to_string(),
        dt: |s| 0.1 / s.value("omega"),
        invariants: |_| vec![("H", 0.5)],
        build: |s| Ok(HarmonicOscillator::problem(s.value("omega"))?.map(|s| mechanical(Scene::HarmonicOscillator(s)))),
    },
    CatalogueEntry {
        name: "pendulum",
        parameters: &[],
        description: |_| "mathematical pendulum in its angle".to_string(),
        dt: |_| 2.0 * PI / 64.0,
        invariants: |_| vec![("H", -0.5)],
        build: |_| Ok(Pendulum::problem().map(|s| mechanical(Scene::Pendulum(s)))),
    },
    CatalogueEntry {
        name: "kepler",
        parameters: &[E],
        description: |s| format!("Kepler orbit, eccentricity {:?}", s.value("e")),
        dt: |s| kepler_dt(s.value("e")),
        invariants: |s| vec![("H", -0.5), ("L", (1.0 - s.value("e").powi(2)).sqrt())],
        build: |s| Ok(Kepler::problem(s.value("e"))?.map(|s| mechanical(Scene::Kepler(s)))),
    },
    CatalogueEntry {
        name: "henon_heiles",
        parameters: &[],
        description: |_| "Hénon–Heiles, H = 0.13".to_string(),
        dt: |_| 0.1,
        invariants: |_| vec![("H", 0.13)],
        build: |_| Ok(HenonHeiles::problem().map(|s| mechanical(Scene::HenonHeiles(s)))),
    },
    CatalogueEntry {
        name: "fermi_pasta_ulam",
        parameters: &[],
        description: |_| "Fermi–Pasta–Ulam chain, ω = 50 (HLW I.5)".to_string(),
        dt: |_| 0.001,
        invariants: |_| vec![("H", 2.00120008), ("I", 1.0)],
        build: |_| Ok(FermiPastaUlam::problem().map(|s| mechanical(Scene::FermiPastaUlam(s)))),
    },
    CatalogueEntry {
        name: "outer_solar_system",
        parameters: &[],
        description: |_| "outer solar system (AU, days, solar masses)".to_string(),
        dt: |_| 50.0,
        invariants: |_| vec![("H", -3.215453183208163e-08)],
        build: |_| Ok(NBody::outer_solar_system().map(|s| mechanical(Scene::NBody(s)))),
    },
    CatalogueEntry {
        name: "double_pendulum",
        parameters: &[],
        description: |_| "double pendulum (configuration-dependent mass)".to_string(),
        dt: |_| 0.01,
        invariants: |_| vec![("E", -40.218179175435154)],
        build: |_| Ok(DoublePendulum::problem().map(|s| general_lagrangian(LagrangianScene::DoublePendulum(s)))),
    },
    CatalogueEntry {
        name: "spherical_pendulum",
        parameters: &[],
        description: |_| "spherical pendulum in (θ, φ); φ cyclic".to_string(),
        dt: |_| 0.01,
        invariants: |_| vec![("E", -0.030489444711168545), ("p_phi", 0.8496881019282854)],
        build: |_| Ok(SphericalPendulum::problem().map(|s| general_lagrangian(LagrangianScene::SphericalPendulum(s)))),
    },
    CatalogueEntry {
        name: "heavy_top",
        parameters: &[],
        description: |_| "heavy symmetric top in Euler angles (θ, φ, ψ); φ and ψ cyclic".to_string(),
        dt: |_| 0.01,
        invariants: |_| {
            vec![
                ("E", 6.25 + 0.3f64.cos()),
                ("p_phi", 2.5 * 0.3f64.cos()),
                ("p_psi", 2.5),
            ]
        },
        build: |_| Ok(HeavyTop::problem().map(|s| general_lagrangian(LagrangianScene::HeavyTop(s)))),
    },
    CatalogueEntry {
        name: "kepler_polar",
        parameters: &[E],
        description: |s| {
            format!(
                "Kepler orbit in polar coordinates (r, θ), eccentricity {:?}; θ cyclic",
                s.value("e")
            )
        },
        dt: |s| kepler_dt(s.value("e")),
        invariants: |s| vec![("E", -0.5), ("p_theta", (1.0 - s.value("e").powi(2)).sqrt())],
        build: |s| Ok(KeplerPolar::problem(s.value("e"))?.map(|s| general_lagrangian(LagrangianScene::KeplerPolar(s)))),
    },
    CatalogueEntry {
        name: "charged_particle",
        parameters: &[real("B", 1.0)],
        description: |s| format!("charged particle in the uniform field B = {:?}", s.value("B")),
        dt: |_| 0.05,
        invariants: |s| vec![("E", 0.5 * s.value("B").powi(2)), ("L", -0.5 * s.value("B"))],
        build: |s| {
            Ok(ChargedParticle::uniform_field(s.value("B"))?
                .map(|s| general_lagrangian(LagrangianScene::ChargedParticle(s))))
        },
    },
    CatalogueEntry {
        name: "charged_particle_nonuniform",
        parameters: &[],
        description: |_| "charged particle in the field B(q) = (1 + |q|²/4) ẑ".to_string(),
        dt: |_| 0.05,
        invariants: |_| vec![("E", 0.5), ("L", -0.4375)],
        build: |_| {
            Ok(ChargedParticle::nonuniform_field().map(|s| general_lagrangian(LagrangianScene::ChargedParticle(s))))
        },
    },
    CatalogueEntry {
        name: "damped_driven_pendulum",
        parameters: &[real("gamma", 0.5), real("amplitude", 1.5), real("drive", 2.0 / 3.0)],
        description: |s| {
            format!(
                "damped driven pendulum, γ = {}, A = {}, Ω = {}",
                general(s.value("gamma")),
                general(s.value("amplitude")),
                general(s.value("drive"))
            )
        },
        dt: |_| 0.01,
        invariants: |_| Vec::new(),
        build: |s| {
            let p = DampedDrivenPendulum::problem(s.value("gamma"), s.value("amplitude"), s.value("drive"))?;
            Ok(p.map(|s| general_lagrangian(LagrangianScene::DampedDrivenPendulum(s))))
        },
    },
    CatalogueEntry {
        name: "cartesian_pendulum",
        parameters: &[],
        description: |_| "the pendulum in Cartesian coordinates on x² + y² = 1".to_string(),
        dt: |_| 0.1,
        invariants: |_| vec![("H", -(2.0f64.cos()))],
        build: |_| Ok(cartesian_pendulum().map(SceneModel::Constrained)),
    },
    CatalogueEntry {
        name: "cartesian_spherical_pendulum",
        parameters: &[],
        description: |_| "the spherical pendulum in Cartesian coordinates on |x| = 1".to_string(),
        dt: |_| 0.01,
        invariants: |_| vec![("H", -0.030489444711168545), ("L_z", 0.8496881019282854)],
        build: |_| Ok(cartesian_spherical_pendulum().map(SceneModel::Constrained)),
    },
    CatalogueEntry {
        name: "planar_chain",
        parameters: &[Parameter {
            name: "links",
            default: 8.0,
            integer: true,
        }],
        description: |s| format!("a planar chain of {} rigid links", s.value("links")),
        dt: |_| 0.01,
        invariants: |_| Vec::new(),
        build: |s| Ok(planar_chain(s.value("links") as usize)?.map(SceneModel::Constrained)),
    },
    CatalogueEntry {
        name: "rigid_body",
        parameters: &[],
        description: |_| "a rigid body in unit quaternions on |q| = 1".to_string(),
        dt: |_| 0.01,
        invariants: |_| Vec::new(),
        build: |_| Ok(RigidBody::problem().map(SceneModel::ConstrainedGeneral)),
    },
    CatalogueEntry {
        name: "bouncing_ball",
        parameters: &[real("g", 9.81), real("h0", 1.0), real("restitution", 1.0)],
        description: |s| {
            format!(
                "a ball bouncing on a floor, g = {}, h₀ = {}, e = {}",
                general(s.value("g")),
                general(s.value("h0")),
                general(s.value("restitution"))
            )
        },
        // At most a fiftieth of the shortest flight, 2eᴷ⁻¹t₁ before the final apex, in N ≡ 5 (mod 10)
        // steps: at e = 1 the k-th impact is then at (2k + 1)N/20 steps, at the fractions α = ¼
        // and ¾ of a step in turn, where the variational law's energy jumps g²h²(1 − 2α)/8 cancel
        // in pairs. A step commensurate with the flight would put every impact at one fraction,
        // and the jumps would add up.
        dt: |s| {
            let (g, h0, e) = (s.value("g"), s.value("h0"), s.value("restitution"));
            let t_end = BouncingBall::horizon(g, h0, e);
            let flight = 2.0 * e.powi(BouncingBall::bounces(e) - 1) * (2.0 * h0 / g).sqrt();
            let n = (steps_to(t_end, flight / 50.0)..).find(|n| n % 10 == 5);
            t_end / n.unwrap_or(1) as f64
        },
        invariants: |s| {
            if s.value("restitution") == 1.0 {
                vec![("H", s.value("g") * s.value("h0"))]
            } else {
                Vec::new()
            }
        },
        build: |s| {
            let p = BouncingBall::problem(s.value("g"), s.value("h0"), s.value("restitution"))?;
            Ok(p.map(|s| mechanical(Scene::BouncingBall(s))))
        },
    },
    CatalogueEntry {
        name: "elliptic_billiard",
        parameters: &[
            real("A", 2.0),
            real("B", 1.0),
            real("x0", 0.3),
            real("y0", 0.1),
            real("px0", 0.6),
            real("py0", 0.8),
        ],
        description: |s| {
            format!(
                "a free particle in the elliptic billiard x²/A² + y²/B² ≤ 1, A = {}, B = {}",
                general(s.value("A")),
                general(s.value("B"))
            )
        },
        // At most a twentieth of the time to cross the short axis.
        dt: |s| {
            let speed = s.value("px0").hypot(s.value("py0"));
            let most = 0.1 * s.value("B") / if speed > 0.0 { speed } else { 1.0 };
            EllipticBilliard::HORIZON / steps_to(EllipticBilliard::HORIZON, most) as f64
        },
        invariants: |s| {
            let (q, p) = ([s.value("x0"), s.value("y0")], [s.value("px0"), s.value("py0")]);
            let table = EllipticBilliard::new(s.value("A"), s.value("B"));
            let focal = table.map_or(f64::NAN, |t| t.focal_product(&q, &p));
            vec![("E", 0.5 * (p[0] * p[0] + p[1] * p[1])), ("L1L2", focal)]
        },
        build: |s| {
            let (q0, p0) = ([s.value("x0"), s.value("y0")], [s.value("px0"), s.value("py0")]);
            let p = EllipticBilliard::problem(s.value("A"), s.value("B"), q0, p0)?;
            Ok(p.map(|s| mechanical(Scene::EllipticBilliard(s))))
        },
    },
    CatalogueEntry {
        name: "rolling_disk",
        parameters: &[real("radius", 1.0), real("turn", 0.7), real("roll", 2.0)],
        description: |s| {
            format!(
                "a vertical disk (a coin) rolling without slipping, R = {}, θ̇ = {}, φ̇ = {}; E, p_θ, p_φ conserved, not p_x, p_y",
                general(s.value("radius")),
                general(s.value("turn")),
                general(s.value("roll"))
            )
        },
        dt: |_| 0.05,
        invariants: |s| {
            let (r, turn, roll) = (s.value("radius"), s.value("turn"), s.value("roll"));
            vec![
                ("E", RollingDisk::energy(r, turn, roll)),
                ("p[2]", 0.25 * r * r * turn),
                ("p[3]", 0.5 * r * r * roll),
            ]
        },
        build: |s| {
            let p = RollingDisk::problem(s.value("radius"), s.value("turn"), s.value("roll"))?;
            Ok(p.map(|s| nonholonomic(NonholonomicScene::RollingDisk(s))))
        },
    },
    CatalogueEntry {
        name: "chaplygin_sleigh",
        parameters: &[real("inertia", 1.0), real("blade", 1.0), real("spin", 1.0)],
        description: |s| {
            format!(
                "the Chaplygin sleigh, I = {}, blade b = {} behind the centre, spinning at ω₀ = {}; E conserved, no momentum",
                general(s.value("inertia")),
                general(s.value("blade")),
                general(s.value("spin"))
            )
        },
        dt: |_| 0.01,
        invariants: |s| {
            let total = s.value("inertia") + s.value("blade").powi(2);
            vec![("E", 0.5 * total * s.value("spin").powi(2))]
        },
        build: |s| {
            let p = ChaplyginSleigh::problem(s.value("inertia"), s.value("blade"), s.value("spin"))?;
            Ok(p.map(|s| nonholonomic(NonholonomicScene::ChaplyginSleigh(s))))
        },
    },
    CatalogueEntry {
        name: "rolling_sphere",
        parameters: &[
            real("alpha", 0.5),
            real("g", 9.81),
            real("radius", 1.0),
            real("vx0", 1.0),
            real("vy0", 0.3),
            real("spin", 1.0),
        ],
        description: |s| {
            format!(
                "a ball rolling on a rough plane inclined at α = {} (Byerly): its centre runs down a parabola at (5/7)g sin α; E, p_φ conserved, not p_x",
                general(s.value("alpha"))
            )
        },
        dt: |_| 0.01,
        invariants: |s| {
            let (vx, vy) = (s.value("vx0"), s.value("vy0"));
            let spin = 0.2 * (s.value("radius") * s.value("spin")).powi(2);
            vec![("E", 0.7 * (vx * vx + vy * vy) + spin), ("p[2]", ball_spin(s))]
        },
        build: |s| {
            let velocity = [s.value("vx0"), s.value("vy0")];
            let (alpha, g, radius) = (s.value("alpha"), s.value("g"), s.value("radius"));
            let p = RollingSphere::incline(alpha, g, radius, velocity, s.value("spin"))?;
            Ok(p.map(|s| nonholonomic(NonholonomicScene::RollingSphere(s))))
        },
    },
    CatalogueEntry {
        name: "ball_on_turntable",
        parameters: &[
            real("omega", 1.0),
            real("radius", 1.0),
            real("x0", 1.0),
            real("y0", 0.0),
            real("vx0", 0.0),
            real("vy0", 0.2),
            real("spin", 1.0),
        ],
        description: |s| {
            format!(
                "a ball rolling on a table turning at Ω = {} (affine constraints): its centre circles at 2Ω/7; J = E − Ω(x p_y − y p_x) and p_φ conserved, not E",
                general(s.value("omega"))
            )
        },
        // About 0.05/Ω, a whole number of steps to t_end = 14π/Ω.
        dt: |s| {
            let t_end = 14.0 * PI / s.value("omega");
            t_end / steps_to(t_end, 0.05 / s.value("omega")) as f64
        },
        invariants: |s| vec![("J", turntable_jacobi(s)), ("p[2]", ball_spin(s))],
        build: |s| {
            let (centre, velocity) = ([s.value("x0"), s.value("y0")], [s.value("vx0"), s.value("vy0")]);
            let p = RollingSphere::turntable(s.value("omega"), s.value("radius"), centre, velocity, s.value("spin"))?;
            Ok(p.map(|s| nonholonomic(NonholonomicScene::RollingSphere(s))))
        },
    },
];

/// The Kepler scenes' step: 2π/200 up to e = 0.6, and beyond it shorter as the pericentre
/// passage, whose time scales as (1 − e)^(3/2): the step resolves it as at e = 0.6 (at
/// e = 0.9, 2π/1600; 2π/200 there loses a verlet orbit, and h/2 too).
fn kepler_dt(e: f64) -> f64 {
    2.0 * PI / 200.0 * ((1.0 - e) / 0.4).powf(1.5).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::general;

    #[test]
    fn general_writes_as_percent_g() {
        assert_eq!(general(0.5), "0.5");
        assert_eq!(general(1.5), "1.5");
        assert_eq!(general(2.0 / 3.0), "0.666667");
        assert_eq!(general(2.0), "2");
        assert_eq!(general(1e-5), "1e-05");
        assert_eq!(general(123456789.0), "1.23457e+08");
        assert_eq!(general(999999.6), "1e+06");
        assert_eq!(general(0.0001), "0.0001");
        assert_eq!(general(0.0), "0");
        assert_eq!(general(f64::NAN), "nan");
        assert_eq!(general(f64::NEG_INFINITY), "-inf");
    }
}
