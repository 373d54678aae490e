// Test kernel: evaluates eval_brdf for a list of cases, so that tests can compare the
// WGSL BRDFs with their CPU twins (tests/integration/bxdf_gpu_twin.rs). Not part of the renderer.

#import types
#import bxdf

struct BrdfCase {
    // Index into `eval_materials`.
    material: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    n: vec4<f32>,
    wi: vec4<f32>,
    wo: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> eval_materials: array<Material>;
@group(0) @binding(1) var<storage, read> cases: array<BrdfCase>;
@group(0) @binding(2) var<storage, read_write> values: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn eval_brdfs(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&cases) {
        return;
    }
    let c = cases[id.x];
    let f = eval_brdf(eval_materials[c.material], c.n.xyz, c.wi.xyz, c.wo.xyz);
    values[id.x] = vec4<f32>(f, 0.0);
}
