//! Small synthetic MERL tables for tests: a diffuse colour plus a specular lobe in theta_h,
//! a few parameters per material, so a handful of tables span a low-dimensional family.

use deepbrdf_data::merl::grid;
use deepbrdf_data::MerlTable;

/// Material `i` of a seeded synthetic family: albedo, lobe strength and width vary with `i`.
pub fn synthetic_table(i: usize) -> MerlTable {
    let f = i as f32;
    let albedo = [0.2 + 0.07 * f, 0.5 - 0.05 * (f % 4.0), 0.1 + 0.1 * (f % 3.0)];
    let strength = 0.5 + 3.0 * ((f * 0.7).sin().abs());
    let width = 0.05 + 0.04 * (f % 5.0);
    MerlTable::from_fn(|h, d, p| {
        let th = grid::theta_h_of(h) as f32;
        let td = grid::theta_d_of(d) as f32;
        let lobe = strength * (-(th * th) / (width * width)).exp() * (1.0 + 0.2 * td.sin())
            + 0.01 * (p as f32 / 180.0);
        [0, 1, 2].map(|c| albedo[c] / std::f32::consts::PI + lobe * (1.0 + 0.1 * c as f32))
    })
}

/// `n` synthetic tables and names.
pub fn synthetic_set(n: usize) -> (Vec<String>, Vec<MerlTable>) {
    ((0..n).map(|i| format!("synthetic-{i}")).collect(), (0..n).map(synthetic_table).collect())
}
