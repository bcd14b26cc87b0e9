//! The resolution heat map's colours on the CPU: the table `heat_color` in
//! `shaders/mesh_common.wgsl` tabulates (linear RGB, one entry per `log2 R` = 0..=12, larger
//! `R` clamped to the last), for legends. `crates/render/tests/gpu/shaders.rs` checks that
//! this copy equals the shader's table number for number.

/// Linear RGB of the heat map at `log2 R` = 0..=12: dark blue, blue, cyan, green, yellow,
/// orange, magenta at 0, 2, 4, …, 12 (mixed in sRGB).
pub const HEAT_COLORS: [[f32; 3]; 13] = [
    [0.0100228, 0.0100228, 0.1706449],
    [0.0143499, 0.0508761, 0.4479884],
    [0.0196066, 0.1328683, 0.8900055],
    [0.0065714, 0.3485102, 0.8377929],
    [0.0000000, 0.6920712, 0.7874123],
    [0.0100228, 0.6920712, 0.2901425],
    [0.0331048, 0.6920712, 0.0508761],
    [0.3069994, 0.7388448, 0.0331048],
    [0.9551046, 0.7874123, 0.0196066],
    [0.9551046, 0.4132082, 0.0125104],
    [0.9551046, 0.1706449, 0.0071944],
    [0.8688995, 0.0732390, 0.1259674],
    [0.7874123, 0.0196066, 0.4479884],
];

/// The heat map's linear colour of a face at resolution `2^log2_r`, as the shader's
/// `heat_color` gives it (clamped to the last entry).
pub fn heat_color(log2_r: u32) -> [f32; 3] {
    HEAT_COLORS[(log2_r as usize).min(HEAT_COLORS.len() - 1)]
}
