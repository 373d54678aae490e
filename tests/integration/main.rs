//! The integration tests, one binary (matklad, "Delete Cargo Integration Tests",
//! 2021): each module is one area's tests, `support` the helpers they share. One
//! binary compiles and links once, and dead helpers are found by the compiler.

mod support;

mod aov;
mod bvh_cpu;
mod bvh_gpu;
mod bxdf_gpu_twin;
mod bxdf_plausibility;
mod cli;
mod corpus;
mod denoise;
mod denoise_oidn;
mod display_pass;
mod emissive_texture;
mod environment;
mod environment_gpu;
mod environment_reference;
mod extremes;
mod frame_loop;
mod fuzz_pipeline;
mod fuzz_scenes;
mod gpu_bench;
mod gpu_memory;
mod gpu_smoke;
mod gpu_vs_cpu;
mod import_fuzz;
mod import_gltf;
mod import_obj;
mod inputs_kept;
mod instancing;
mod layering;
mod layout;
mod load_time;
mod material_errors;
#[cfg(target_os = "linux")]
mod memory_cap;
mod model_alpha;
mod model_shading;
mod noise;
mod path_gpu;
mod path_reference;
mod path_tracing;
mod radiometry;
mod ray_query;
mod recipes;
mod sampler_chi2;
mod sampling_bias;
mod sampling_gpu_twin;
mod scene_errors;
mod scene_models;
mod shader_modules;
mod shading_normals;
mod specialisation;
mod stress_scenes;
mod texture_filtering;
mod thin_lens;
mod tiles;
mod uniform_records;
mod unrolled;
mod uv_wrap_gpu;
mod viewer;
