// The built-in denoiser: an edge-avoiding à-trous wavelet filter (Dammertz, Sewtz,
// Hanika and Lensch, HPG 2010) guided by the auxiliary passes and each pixel's
// variance (the edge-stopping functions of SVGF, Schied et al., HPG 2017, section 4.4)
// on albedo-demodulated radiance. Twin of src/denoise.rs, where the derivations are:
// the same functions, in f32, summing in the same order.
//
// The host dispatches, over one image: prepare_film_signal (a film's mean, variance
// and passes; a caller's image is uploaded instead), demodulate_signal, one
// atrous_pass per iteration with frame step 2^i, ping-ponging between `signal_in` and
// `signal_out`, and remodulate_signal into `denoised`.

#import types
#import color

@group(0) @binding(0) var<uniform> params: DenoiseUniforms;
// The film's mean radiance (prepare_film_signal).
@group(0) @binding(1) var film_radiance: texture_2d<f32>;
// The film's sums: (radiance sum, luminance m2) per pixel, then the passes' sums,
// (albedo, depth) and (normal, samples) per pixel (aov.wgsl).
@group(0) @binding(2) var<storage, read> film_sums: array<vec4<f32>>;
// Per pixel: (albedo, depth) and (normal, 0), the guides.
@group(0) @binding(3) var<storage, read_write> guides: array<vec4<f32>>;
// The signal a step reads and the one it writes: (radiance or demodulated radiance,
// variance of its luminance) per pixel.
@group(0) @binding(4) var<storage, read> signal_in: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> signal_out: array<vec4<f32>>;
@group(0) @binding(6) var denoised: texture_storage_2d<rgba32float, write>;

// The B3-spline taps of the à-trous kernel. Twin of KERNEL.
const KERNEL = array<f32, 5>(1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);
// Darker albedos are not demodulated. Twin of MIN_ALBEDO.
const MIN_ALBEDO: f32 = 1e-3;
// Variances above this (a pixel of fewer than two samples has an infinite one) are
// taken as this. Twin of MAX_VARIANCE.
const MAX_VARIANCE: f32 = 1e30;

// The factor a pixel's radiance is divided by: its albedo's mean, or 1 for albedos
// too dark. Twin of demodulation_scale.
fn demodulation_scale(albedo: vec3<f32>) -> f32 {
    let mean = (albedo.x + albedo.y + albedo.z) / 3.0;
    return select(1.0, mean, mean > MIN_ALBEDO);
}

// Radiance divided by its albedo, per channel where the channel is bright enough.
// Twin of demodulate.
fn demodulate(radiance: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    return select(radiance, radiance / albedo, albedo > vec3<f32>(MIN_ALBEDO));
}

// The inverse of demodulate. Twin of remodulate.
fn remodulate(signal: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    return select(signal, signal * albedo, albedo > vec3<f32>(MIN_ALBEDO));
}

fn tap_index(x: i32, y: i32) -> u32 {
    return u32(y) * params.width + u32(x);
}

// The variance of pixel (x, y) blurred by a 3x3 Gaussian (SVGF section 4.4). Twin of
// blurred_variance.
fn blurred_variance(x: i32, y: i32) -> f32 {
    let gauss = array<f32, 3>(0.25, 0.5, 0.25);
    let width = i32(params.width);
    let height = i32(params.height);
    var sum = 0.0;
    var weights = 0.0;
    for (var j = 0; j < 3; j++) {
        let qy = y + j - 1;
        if qy < 0 || qy >= height {
            continue;
        }
        for (var i = 0; i < 3; i++) {
            let qx = x + i - 1;
            if qx < 0 || qx >= width {
                continue;
            }
            let w = gauss[i] * gauss[j];
            sum += w * signal_in[tap_index(qx, qy)].w;
            weights += w;
        }
    }
    return sum / weights;
}

// `n` scaled to unit length, or zero for a zero normal. Twin of unit_normal.
fn unit_normal(n: vec3<f32>) -> vec3<f32> {
    let length = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    return select(vec3<f32>(0.0), n / length, length > 0.0);
}

// The edge-stopping weight of tap q for pixel p (SVGF eq. 3-6): normals (their
// directions), depth and luminance, and albedo; 1 for the pixel itself. Twin of edge_weight.
fn edge_weight(p: u32, q: u32, l_p: f32, signal_q: vec3<f32>, sigma_l: f32, step: i32) -> f32 {
    if p == q {
        return 1.0;
    }
    let n_p = unit_normal(guides[2u * p + 1u].xyz);
    let n_q = unit_normal(guides[2u * q + 1u].xyz);
    let cosine = max(n_p.x * n_q.x + n_p.y * n_q.y + n_p.z * n_q.z, 0.0);
    let z_p = guides[2u * p].w;
    let z_q = guides[2u * q].w;
    // Escaped rays have no normal: they filter only with each other.
    var w_normal = pow(cosine, params.sigma_normal);
    if z_p <= 0.0 && z_q <= 0.0 {
        w_normal = 1.0;
    }
    let scale = params.sigma_depth * max(max(z_p, z_q), 1e-6) * f32(step);
    let w_depth = exp(-abs(z_p - z_q) / scale);
    let l_q = luminance(signal_q);
    let w_luminance = exp(-abs(l_p - l_q) / (sigma_l + 1e-10));
    let a_p = guides[2u * p].xyz;
    let a_q = guides[2u * q].xyz;
    let albedo_difference = (abs(a_p.x - a_q.x) + abs(a_p.y - a_q.y) + abs(a_p.z - a_q.z)) / 3.0;
    let w_albedo = exp(-albedo_difference / params.sigma_albedo);
    return w_normal * w_depth * w_luminance * w_albedo;
}

// A film's pixel as the filter's input: its mean radiance, the variance of its mean's
// luminance (the square of the noise estimate's standard error, noise.wgsl) and its
// passes' means, over the samples its passes counted.
@compute @workgroup_size(8, 8, 1)
fn prepare_film_signal(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let p = id.y * params.width + id.x;
    let pixels = params.width * params.height;
    let albedo_depth = film_sums[pixels + 2u * p];
    let normal_samples = film_sums[pixels + 2u * p + 1u];
    let n = normal_samples.w;
    let scale = 1.0 / max(n, 1.0);
    guides[2u * p] = albedo_depth * scale;
    guides[2u * p + 1u] = vec4<f32>(normal_samples.xyz * scale, 0.0);
    var variance = MAX_VARIANCE;
    if n >= 2.0 {
        variance = max(film_sums[p].w, 0.0) / (n * (n - 1.0));
    }
    signal_out[p] = vec4<f32>(textureLoad(film_radiance, vec2<i32>(id.xy), 0).rgb, variance);
}

// Divides each pixel's radiance by its albedo and its variance by the square of the
// albedo's mean. The first step of denoise.
@compute @workgroup_size(8, 8, 1)
fn demodulate_signal(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let p = id.y * params.width + id.x;
    let albedo = guides[2u * p].xyz;
    let input = signal_in[p];
    let scale = demodulation_scale(albedo);
    signal_out[p] = vec4<f32>(demodulate(input.xyz, albedo),
                          min(input.w, MAX_VARIANCE) / (scale * scale));
}

// One pass of the filter with taps params.step pixels apart: each pixel's weighted
// mean of its 5x5 taps and the variance of that mean (SVGF eq. 7). Twin of
// atrous_pass.
@compute @workgroup_size(8, 8, 1)
fn atrous_pass(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let x = i32(id.x);
    let y = i32(id.y);
    let width = i32(params.width);
    let height = i32(params.height);
    let step = i32(params.step);
    let p = tap_index(x, y);
    let l_p = luminance(signal_in[p].xyz);
    // The luminance edge stop scales with the pixel's noise, blurred over its 3x3
    // neighbourhood.
    let sigma_l = params.sigma_luminance * sqrt(blurred_variance(x, y));
    var sum = vec3<f32>(0.0);
    var sum_var = 0.0;
    var weights = 0.0;
    for (var j = 0; j < 5; j++) {
        let qy = y + (j - 2) * step;
        if qy < 0 || qy >= height {
            continue;
        }
        for (var i = 0; i < 5; i++) {
            let qx = x + (i - 2) * step;
            if qx < 0 || qx >= width {
                continue;
            }
            let q = tap_index(qx, qy);
            let tap = signal_in[q];
            let w = KERNEL[i] * KERNEL[j] * edge_weight(p, q, l_p, tap.xyz, sigma_l, step);
            sum += w * tap.xyz;
            sum_var += w * w * tap.w;
            weights += w;
        }
    }
    signal_out[p] = vec4<f32>(sum / weights, sum_var / (weights * weights));
}

// Multiplies the filtered signal by each pixel's albedo again and writes it to the
// denoised image. The last step of denoise.
@compute @workgroup_size(8, 8, 1)
fn remodulate_signal(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let p = id.y * params.width + id.x;
    let radiance = remodulate(signal_in[p].xyz, guides[2u * p].xyz);
    textureStore(denoised, vec2<i32>(id.xy), vec4<f32>(radiance, 1.0));
}
