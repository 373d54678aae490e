// The bindings of the trace kernels (group 0), twins of `binding` in
// src/gpu/pipelines.rs; but for those declared where they are read (`images`,
// `emitters`, `environment`) and the record arrays, which the host declares as storage
// or uniform arrays (the module `records`, src/gpu/cpu_device/uniform_records.rs).

#import types

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
// binding 1: `spheres`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 2: `planes`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 3: `polygons`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 4: `polygon_points`, each polygon vertex projected for the inside test (the
// plane's dropped axis removed), read by polygon_point(i); declared by
// src/gpu/cpu_device/uniform_records.rs.
// binding 5: `triangles`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 6: `materials`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 7: `lights`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
@group(0) @binding(8) var linear_output: texture_storage_2d<rgba32float, write>;
@group(0) @binding(9) var<storage, read_write> counters: Counters;
// Each finished pixel's sample sum in xyz and its luminance m2 in w (noise.wgsl)
// when frame.flags has FLAG_STORE_SUM, and the sums a pixel starts from when
// frame.first_sample > 0: progressive rendering.
@group(0) @binding(10) var<storage, read_write> accumulation: array<vec4<f32>>;
// binding 11: `images`, declared by texture.wgsl.
// binding 12: `bvh_nodes`, a storage or a uniform array, declared by src/gpu/cpu_device/uniform_records.rs.
// binding 13: `bvh_prims`, read by prim_ref(i); declared by src/gpu/cpu_device/uniform_records.rs.
@group(0) @binding(14) var<storage, read_write> paths: array<PathState>;
// Each slot's bounce stack of frame.stack_size entries (interleaved across slots).
@group(0) @binding(15) var<storage, read_write> ray_stack: array<StackEntry>;
@group(0) @binding(16) var<storage, read_write> traces: array<TraceRay>;
// Each slot's traversal stack of MAX_TRAVERSAL_STACK entries of two words, a child
// word and its entry distance's bits (interleaved across slots: traverse.wgsl).
@group(0) @binding(17) var<storage, read_write> traversal_stack: array<u32>;
// Vertex normals and texture coordinates of mesh triangles (Triangle.attributes).
@group(0) @binding(18) var<storage, read> triangle_attributes: array<TriangleAttributes>;
// binding 19: `emitters`, declared by area_lights.wgsl.
// binding 20: `environment`, declared by environment.wgsl.
// binding 21: `scene_tlas`, declared by ray_query.wgsl.
// binding 22: `node_texels`, the BVH nodes as texels where the scene's features have
// node_texture, read by load_wide_node(i) (which reads `bvh_nodes` otherwise);
// declared by src/gpu/cpu_device/node_texture.rs.
