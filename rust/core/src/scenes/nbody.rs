use super::{Problem, State};
use crate::memory::check_allocation;
use crate::model::{Generator, Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// Gravitational N-body problem in 3 dimensions, H = Σ|pᵢ|²/2mᵢ − G Σᵢ<ⱼ mᵢmⱼ/|xᵢ − xⱼ|, with
/// q = (x₁, …, x_N) body by body; translation and rotation invariant.
#[derive(Clone, Debug)]
pub struct NBody {
    g: f64,
    masses: Vec<f64>,
    /// Products G·mᵢ·mⱼ for i < j, row by row: the force loop reads them in order.
    gmm: Vec<f64>,
    mass: Mass,
}

impl NBody {
    pub fn new(g: f64, masses: Vec<f64>) -> Result<Self, Error> {
        if !(g.is_finite() && g > 0.0) {
            return Err(Error::invalid("G", format!("must be finite and positive, got {g}")));
        }
        if masses.len() < 2 {
            return Err(Error::invalid("masses", "need at least two bodies"));
        }
        // The table of pairs, N(N − 1)/2 products.
        let n = masses.len();
        check_allocation("masses", n.saturating_mul(n - 1) / 2, std::mem::size_of::<f64>())?;
        let mass = Mass::diagonal(masses.iter().flat_map(|m| [*m; 3]).collect())?;
        let gmm = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .map(|(i, j)| g * masses[i] * masses[j])
            .collect();
        Ok(NBody { g, masses, gmm, mass })
    }

    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    pub fn gravitational_constant(&self) -> f64 {
        self.g
    }

    /// The outer solar system of HLW I.2.4 (Sun with the inner planets, Jupiter, Saturn, Uranus,
    /// Neptune, Pluto; AU, days, solar masses), to t = 500 000 days, against the reference
    /// state of the GNI test codes.
    pub fn outer_solar_system() -> Problem<Self> {
        const G: f64 = 0.000295912208286;
        const MASSES: [f64; 6] = [
            1.00000597682,
            0.000954786104043,
            0.000285583733151,
            4.37273164546e-05,
            5.17759138449e-05,
            7.692307692307693e-09,
        ];
        const X0: [[f64; 3]; 6] = [
            [0.0, 0.0, 0.0],
            [-3.5023653, -3.8169847, -1.5507963],
            [9.0755314, -3.0458353, -1.6483708],
            [8.310142, -16.2901086, -7.2521278],
            [11.4707666, -25.7294829, -10.8169456],
            [-15.5387357, -25.2225594, -3.1902382],
        ];
        const V0: [[f64; 3]; 6] = [
            [0.0, 0.0, 0.0],
            [0.00565429, -0.0041249, -0.00190589],
            [0.00168318, 0.00483525, 0.00192462],
            [0.00354178, 0.00137102, 0.00055029],
            [0.0028893, 0.00114527, 0.00039677],
            [0.00276725, -0.00170702, -0.00136504],
        ];
        const X_REF: [[f64; 3]; 6] = [
            [3.084118473380683, -1.227726356581642, -0.6162537634647217],
            [7.766584086800482, 0.2531065754551048, -0.09410571402013185],
            [-5.564967162844037, 1.674849740822012, 0.9767232069533176],
            [19.63899572895227, 8.95850455228646, 3.611839157057347],
            [24.93570870305177, 17.69518676153705, 6.583785164549242],
            [31.78592511375764, 38.63618958160644, 3.192794169732889],
        ];
        const V_REF: [[f64; 3]; 6] = [
            [9.417379703028725e-06, -7.855256238249194e-06, -3.646926313230521e-06],
            [-0.002495503201917009, 0.006896467194473328, 0.003007950247474123],
            [-0.002255335935351989, -0.004905913854771086, -0.001938473641716708],
            [-0.002186170231167942, 0.002817177012110666, 0.001262882639181183],
            [-0.002148728705895163, 0.002128650077635786, 0.0009248501411662923],
            [-0.001675173186229401, 0.001011833320388655, 0.000823180003857652],
        ];
        let momenta =
            |v: &[[f64; 3]; 6]| -> Vec<f64> { v.iter().zip(MASSES).flat_map(|(vi, m)| vi.map(|x| m * x)).collect() };
        let t_end = 500_000.0;
        Problem {
            system: Self::new(G, MASSES.to_vec()).expect("valid data"),
            initial: State {
                t: 0.0,
                q: X0.concat(),
                p: momenta(&V0),
            },
            t_end,
            reference: Some((
                State {
                    t: t_end,
                    q: X_REF.concat(),
                    p: momenta(&V_REF),
                },
                "Hairer, Lubich & Wanner, GNI I.2.4; GNI test codes (problem.f)",
            )),
        }
    }
}

impl MechanicalSystem for NBody {
    fn dim(&self) -> usize {
        3 * self.masses.len()
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let mut v = 0.0;
        let mut k = 0;
        let n = self.masses.len();
        for i in 0..n {
            for j in i + 1..n {
                let d = [
                    q[3 * i] - q[3 * j],
                    q[3 * i + 1] - q[3 * j + 1],
                    q[3 * i + 2] - q[3 * j + 2],
                ];
                v -= self.gmm[k] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                k += 1;
            }
        }
        Ok(v)
    }
    /// ∂V/∂xᵢ = Σⱼ G mᵢmⱼ (xᵢ − xⱼ)/|xᵢ − xⱼ|³, each pair visited once.
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        let mut gmm = self.gmm.iter();
        for i in 0..self.masses.len() {
            let (head, tail) = grad.split_at_mut(3 * i + 3);
            let xi = &q[3 * i..3 * i + 3];
            let mut gi = [0.0; 3];
            for ((xj, gj), k) in q[3 * i + 3..]
                .chunks_exact(3)
                .zip(tail.chunks_exact_mut(3))
                .zip(&mut gmm)
            {
                let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let f = k / (r2 * r2.sqrt());
                for a in 0..3 {
                    gi[a] += f * d[a];
                    gj[a] -= f * d[a];
                }
            }
            for (g, v) in head[3 * i..].iter_mut().zip(gi) {
                *g += v;
            }
        }
        Ok(())
    }
    fn symmetries(&self) -> Vec<Generator> {
        (0..3)
            .map(|axis| Generator::Translation { axis, spatial_dim: 3 })
            .chain((0..3).map(|axis| Generator::Rotation { axis, spatial_dim: 3 }))
            .collect()
    }
}
