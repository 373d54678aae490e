// Importance sampling of tabulated BRDF maps by inverse CDF, for the path integrator.
// CPU twin: src/cpu/tabulated.rs (same function names; the sampler and its density
// are derived there), over the tables of src/accel/brdf_map_cdf.rs: texel (x, y) of
// the inverse-CDF table of an N×N map is the cumulative probability of the bands
// θi < θ_x for the outgoing angle θr = θ_y, in the alpha channel of the map's own
// layer of `images` (texture.wgsl), the same f32 values the CPU reads.

#import math
#import brdf_map_cdf
#import sample

// The probability of drawing from the cosine distribution instead of the map's. Twin
// of TABULATED_COSINE_PROBABILITY.
const TABULATED_COSINE_PROBABILITY: f32 = 0.1;

// θ_b = b/(n−1)·π/2, the angle of texel b of an n-texel axis, and its cosine. Twin of
// grid_angle.
fn grid_angle(b: u32, n: u32) -> vec2<f32> {
    let theta = f32(b) * ((0.5 * PI) / f32(n - 1u));
    return vec2<f32>(theta, cos(theta));
}

// The cell b (θ_b ≤ θ < θ_{b+1}) of an n-texel axis holding the angle of cosine
// z ∈ [0, 1]: guessed from acos z, then checked against the cosines of the cell's ends,
// so that an approximate acos moves no direction across an edge. Twin of brdf_map_cell.
fn brdf_map_cell(n: u32, z: f32) -> u32 {
    let last = f32(n - 1u);
    let theta = acos(z);
    var cell = u32(min(floor(clamp(theta / (0.5 * PI), 0.0, 1.0) * last), last - 1.0));
    if cell > 0u && z > grid_angle(cell, n).y {
        cell -= 1u;
    } else if cell + 2u < n && z <= grid_angle(cell + 1u, n).y {
        cell += 1u;
    }
    return cell;
}

// The two rows the sampler mixes for the outgoing cosine: the first, and the weight w
// of the second.
struct BrdfMapRows {
    y0: u32,
    w: f32,
}

// Twin of brdf_map_rows: the row y with θ_y ≤ θr < θ_{y+1}, and w = (cos θ_y − cos θr) /
// (cos θ_y − cos θ_{y+1}), the denominator as 2 sin((θ_y + θ_{y+1})/2) sin(Δ/2); no acos
// decides the row choice's threshold.
fn brdf_map_rows(n: u32, cos_o: f32) -> BrdfMapRows {
    let z = clamp(cos_o, 0.0, 1.0);
    let y = brdf_map_cell(n, z);
    let half_step = 0.5 * ((0.5 * PI) / f32(n - 1u));
    let width = 2.0 * sin(f32(2u * y + 1u) * half_step) * sin(half_step);
    return BrdfMapRows(y, clamp((grid_angle(y, n).y - z) / width, 0.0, 1.0));
}

// A local incident direction from the map's sampler: the row by u_row (weights from
// brdf_map_rows), the band by binary search of the row's cumulative table with u.x (pbrt-v4
// §A.4.2), sin² θ uniform over the band (the density ∝ cos θ inside it), the azimuth by
// u.y. Twin of sample_brdf_map_direction.
fn sample_brdf_map_direction(layer: u32, n: u32, cos_o: f32, u_row: f32, u: vec2<f32>) -> vec3<f32> {
    let rows = brdf_map_rows(n, cos_o);
    var row = rows.y0 + 1u;
    if u_row < 1.0 - rows.w {
        row = rows.y0;
    }
    // cdf[0] = 0 <= u.x < 1 = cdf[n − 1]: at most log2(n) steps.
    var lo = 0u;
    var hi = n - 1u;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if brdf_map_cdf_value(layer, mid, row) <= u.x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c0 = brdf_map_cdf_value(layer, lo, row);
    let c1 = brdf_map_cdf_value(layer, lo + 1u, row);
    let t = (u.x - c0) / (c1 - c0);
    let edge = grid_angle(lo, n);
    let ds = band_projected_solid_angle(lo, n);
    let sin_squared = sin(edge.x) * sin(edge.x) + t * ds;
    let cos_squared = edge.y * edge.y - t * ds;
    let sin_theta = sqrt(max(sin_squared, 0.0));
    let cos_theta = sqrt(max(cos_squared, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// The density per steradian of sample_brdf_map_direction at the local wi:
// ((1 − w) P_y(b) + w P_{y+1}(b)) · cos θi / (π ΔS_b). Twin of pdf_brdf_map_direction.
fn pdf_brdf_map_direction(layer: u32, n: u32, cos_o: f32, wi: vec3<f32>) -> f32 {
    if wi.z <= 0.0 {
        return 0.0;
    }
    let band = brdf_map_cell(n, min(wi.z, 1.0));
    let rows = brdf_map_rows(n, cos_o);
    let p0 = brdf_map_cdf_value(layer, band + 1u, rows.y0) - brdf_map_cdf_value(layer, band, rows.y0);
    let p1 = brdf_map_cdf_value(layer, band + 1u, rows.y0 + 1u) - brdf_map_cdf_value(layer, band, rows.y0 + 1u);
    let probability = (1.0 - rows.w) * p0 + rows.w * p1;
    return probability * wi.z / (PI * band_projected_solid_angle(band, n));
}

// A local incident direction for a tabulated BRDF seen from the local wo: the cosine
// sampler with probability TABULATED_COSINE_PROBABILITY, else the map's, its row from
// u_lobe rescaled to [0, 1). Twin of sample_tabulated.
fn sample_tabulated(layer: u32, n: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> vec3<f32> {
    if u_lobe < TABULATED_COSINE_PROBABILITY {
        return sample_cosine_hemisphere(u);
    }
    let u_row = (u_lobe - TABULATED_COSINE_PROBABILITY) / (1.0 - TABULATED_COSINE_PROBABILITY);
    return sample_brdf_map_direction(layer, n, wo.z, u_row, u);
}

// The density of sample_tabulated: the mixture of the cosine density and the map's.
// Twin of pdf_tabulated.
fn pdf_tabulated(layer: u32, n: u32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    return TABULATED_COSINE_PROBABILITY * pdf_cosine_hemisphere(wi)
        + (1.0 - TABULATED_COSINE_PROBABILITY) * pdf_brdf_map_direction(layer, n, wo.z, wi);
}
