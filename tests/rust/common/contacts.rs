//! Native contacts of the tests: the floor and circles (`allocation.rs` and the impacts bench,
//! `benches/impacts.rs`, take this file by its path).

use varmech::integrators::{Contact, Contacts, Law, NativeSurface};

/// The wall q_`coordinate` = `value`, native, as the contact `name` of restitution e under `law`.
pub fn wall(coordinate: usize, value: f64, restitution: f64, law: Law, name: &str) -> Contact<'static> {
    Contact {
        surface: Box::new(NativeSurface::Wall { coordinate, value }),
        restitution,
        law,
        friction: None,
        name: name.into(),
    }
}

/// The circle |q| = `radius` in the plane of q₀ and q₁, a native ellipsoid held from `inside` or
/// outside, as the contact `name` of restitution e under `law`.
pub fn ellipsoid(radius: f64, inside: bool, restitution: f64, law: Law, name: &str) -> Contact<'static> {
    Contact {
        surface: Box::new(NativeSurface::Ellipsoid {
            coordinates: vec![0, 1],
            centre: vec![0.0, 0.0],
            semi_axes: vec![radius, radius],
            inside,
        }),
        restitution,
        law,
        friction: None,
        name: name.into(),
    }
}

/// The floor q₀ = 0 ([`wall`]) alone, named "floor".
pub fn floor(restitution: f64, law: Law) -> Contacts<'static> {
    Contacts::new(vec![wall(0, 0.0, restitution, law, "floor")]).unwrap()
}

/// The circle ([`ellipsoid`]) alone.
pub fn circle(radius: f64, inside: bool, restitution: f64, law: Law, name: &str) -> Contacts<'static> {
    Contacts::new(vec![ellipsoid(radius, inside, restitution, law, name)]).unwrap()
}

/// The circular billiard's table |q| ≤ `radius`, elastic (e = 1) under `law`.
pub fn table(radius: f64, law: Law) -> Contacts<'static> {
    circle(radius, true, 1.0, law, "table")
}
