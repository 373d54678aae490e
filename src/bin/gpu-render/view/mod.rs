//! `gpu-render view SCENE`: a window that shows the scene rendered progressively
//! through the library's frame loop (`Renderer`, `GpuScene`, `Film`), as an
//! embedding application would: one sample per pixel per frame by default, the film
//! restarting whenever the camera moves. Orbit (left drag), pan (right or middle
//! drag) and zoom (wheel) around the camera's look-at point; `S` saves what the
//! window shows; the scene file is reloaded when it changes; `--frames N
//! --screenshot OUT.png` renders N frames through the window and its surface, writes
//! what the window shows and exits (the headless test, under Xvfb). docs/viewer.md.
//!
//! Every frame draws the film into an offscreen texture of the surface's format and
//! copies that to the surface texture (or, where the surface cannot be copied into,
//! draws the film a second time into it): surface textures cannot be read back, and
//! the offscreen texture is what the screenshot and `S` read.

mod orbit;
mod watch;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use gpu_render::gpu::{
    AdapterChoice, Film, GpuScene, Renderer, RendererOptions, read_texture, select_adapter,
};
use gpu_render::low_level::denoise::DenoiseSettings;
use gpu_render::output;
use gpu_render::scene::Camera;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::args::{SettingsArgs, ViewArgs};
use crate::loading::{LoadArgs, Loaded};
use gpu_render::low_level::input::InputFile;
use watch::SceneWatcher;

/// Pixels of wheel scrolling that count as one line (touchpads report pixels).
const PIXELS_PER_LINE: f64 = 40.0;
/// How many times in a row the last `--frames` frame may find no surface texture.
const MAX_SKIPPED_FRAMES: u32 = 100;
/// How often the title is rewritten, at most.
const TITLE_INTERVAL: Duration = Duration::from_millis(250);
/// The span over which the title's Mrays/s is measured, at least (passes complete
/// a few times a second).
const RATE_INTERVAL: Duration = Duration::from_secs(1);

/// Runs the viewer until its window is closed (or `--frames` are done).
pub fn run(args: &ViewArgs) -> Result<()> {
    if let Some(path) = &args.screenshot {
        if args.frames.is_none() {
            bail!("--screenshot needs --frames N: the number of frames to render first");
        }
        if output::check_output_path(path)? != output::OutputFormat::Png {
            bail!("{}: --screenshot writes a .png", path.display());
        }
        output::check_not_an_input(path, [(args.scene.as_path(), "scene file")])?;
    }
    crate::apply_overrides(&args.settings, crate::minimal_settings(), None)?;
    // Stamped before the load, so that an edit made while the window opens counts.
    let watcher = SceneWatcher::new(&args.scene);
    let loaded = load_view_scene(args)?;
    if let Some(path) = &args.screenshot {
        crate::loading::check_inputs_survive(path, &args.scene, &loaded.scene, &loaded.inputs)?;
    }
    let event_loop = EventLoop::new().context(
        "cannot open a window: no display server (set DISPLAY or WAYLAND_DISPLAY, or run \
         under xvfb-run)",
    )?;
    let mut app = App {
        args,
        pending: Some((loaded, watcher)),
        viewer: None,
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    match app.error {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

/// Loads the scene file (or model file) with the command-line overrides.
fn load_view_scene(args: &ViewArgs) -> Result<Loaded> {
    crate::loading::load_any(
        &args.scene,
        &view_load_args(&args.settings, args.sandbox, args.quiet),
    )
}

/// How the viewer loads: no memory cap (the window shows what fits).
fn view_load_args(settings: &SettingsArgs, sandbox: bool, quiet: bool) -> LoadArgs<'_> {
    LoadArgs {
        settings,
        sandbox,
        quiet,
        max_memory: None,
    }
}

/// The winit application: the window and its GPU state once the event loop has
/// started, and the error that ended it.
struct App<'a> {
    args: &'a ViewArgs,
    /// The scene to open the window with, and its file's watcher.
    pending: Option<(Loaded, SceneWatcher)>,
    viewer: Option<Viewer>,
    error: Option<anyhow::Error>,
}

impl App<'_> {
    /// Stops the event loop with `error` (the first one is kept).
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error.get_or_insert(error);
        event_loop.exit();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some((loaded, watcher)) = self.pending.take() else {
            return;
        };
        match Viewer::new(event_loop, self.args, loaded, watcher) {
            Ok(viewer) => {
                viewer.window.request_redraw();
                self.viewer = Some(viewer);
            }
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(viewer) = self.viewer.as_mut() else {
            return;
        };
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => viewer.resize(size),
            WindowEvent::RedrawRequested => match viewer.redraw() {
                Ok(Done::Yes) => {
                    event_loop.exit();
                    Ok(())
                }
                Ok(Done::No) => Ok(()),
                Err(error) => Err(error),
            },
            WindowEvent::CursorMoved { position, .. } => {
                viewer.cursor_moved(position);
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                viewer.mouse_button(button, state == ElementState::Pressed);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / PIXELS_PER_LINE,
                };
                viewer.move_camera(|camera| orbit::zoom(camera, lines));
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed && !event.repeat =>
            {
                match event.logical_key.as_ref() {
                    Key::Character(c) if c.eq_ignore_ascii_case("s") => viewer.save(),
                    Key::Character(c) if c.eq_ignore_ascii_case("n") => viewer.show_noise(),
                    Key::Character(c) if c.eq_ignore_ascii_case("d") => viewer.toggle_denoise(),
                    Key::Named(NamedKey::Escape) => {
                        event_loop.exit();
                        Ok(())
                    }
                    Key::Character(c) if c.eq_ignore_ascii_case("q") => {
                        event_loop.exit();
                        Ok(())
                    }
                    _ => Ok(()),
                }
            }
            _ => Ok(()),
        };
        if let Err(error) = result {
            self.fail(event_loop, error);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(viewer) = self.viewer.as_mut() else {
            return;
        };
        viewer.reload_if_changed();
        if viewer.wants_frames() {
            event_loop.set_control_flow(ControlFlow::Wait);
            viewer.window.request_redraw();
        } else {
            // Converged: wake up only to look at the scene file.
            event_loop.set_control_flow(ControlFlow::WaitUntil(
                Instant::now() + Duration::from_millis(250),
            ));
        }
    }
}

/// Whether `--frames` are done.
enum Done {
    Yes,
    No,
}

/// Which drag is in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Drag {
    Orbit,
    Pan,
}

/// The window, its surface and the frame loop's objects.
struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// Whether the offscreen image is copied to the surface (else drawn twice).
    copy_to_surface: bool,
    device: wgpu::Device,
    queue: wgpu::Queue,
    renderer: Renderer,
    scene: GpuScene,
    film: Film,
    /// The film's size as a fraction of the window's (`--scale`).
    scale: f64,
    /// What the window shows, in the surface's format.
    offscreen: wgpu::Texture,
    /// The camera of the scene file as last loaded (a reload that changes it wins
    /// over the interactive camera).
    file_camera: Camera,
    scene_path: PathBuf,
    /// Every file the last load read: `S` never saves over one of them.
    inputs: Vec<InputFile>,
    settings_args: ViewArgsSettings,
    samples_per_frame: u32,
    max_samples: u32,
    frames_left: Option<u32>,
    screenshot: Option<PathBuf>,
    watcher: SceneWatcher,
    /// The last frame's submission: the next frame waits for it, so that at most two
    /// frames are queued on the GPU.
    in_flight: Option<wgpu::SubmissionIndex>,
    /// Rays traced by the film at a moment, for Mrays/s over the time since.
    rate_mark: (Instant, u64),
    /// The Mrays/s shown.
    mrays_per_second: f64,
    title_written: Option<Instant>,
    /// A reload error or a saved file, shown in the title.
    status: Option<String>,
    frames_drawn: u32,
    first_frame: Option<Instant>,
    cursor: PhysicalPosition<f64>,
    drag: Option<(Drag, PhysicalPosition<f64>)>,
    /// Whether the renderer records the passes the denoiser needs (`--denoise`).
    can_denoise: bool,
    /// Whether the window shows the film denoised (the D key).
    denoised: bool,
}

/// What a reload needs of the command line.
struct ViewArgsSettings {
    settings: crate::args::SettingsArgs,
    sandbox: bool,
    quiet: bool,
}

impl Viewer {
    fn new(
        event_loop: &ActiveEventLoop,
        args: &ViewArgs,
        loaded: Loaded,
        watcher: SceneWatcher,
    ) -> Result<Self> {
        let Loaded { scene, inputs, .. } = loaded;
        let (width, height) = (scene.render.width, scene.render.height);
        let window = Arc::new(
            event_loop
                .create_window(
                    Window::default_attributes()
                        .with_title(title_name(&args.scene))
                        .with_inner_size(PhysicalSize::new(width, height)),
                )
                .context("cannot create a window")?,
        );
        let mut instance_desc = wgpu::InstanceDescriptor::new_with_display_handle(Box::new(
            event_loop.owned_display_handle(),
        ));
        instance_desc.backends = viewer_backends();
        let instance = wgpu::Instance::new(instance_desc);
        let surface = instance
            .create_surface(Arc::clone(&window))
            .context("cannot create a wgpu surface for the window")?;
        let adapter = match &args.adapter {
            None => pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: Some(&surface),
                ..Default::default()
            }))
            .context("no GPU adapter can present to this window")?,
            Some(choice) => choose_adapter(&instance, viewer_backends(), &surface, choice)?,
        };
        // Ray queries where the adapter offers them (`RendererOptions::traversal`).
        let (ray_query, experimental_features) =
            gpu_render::gpu::ray_query_features(adapter.features());
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("gpu-render viewer"),
            required_limits: Renderer::required_limits(&adapter.limits()),
            required_features: Renderer::optional_features(adapter.features()) | ray_query,
            experimental_features,
            ..Default::default()
        }))
        .context("cannot open the GPU device")?;
        let size = window.inner_size();
        let (config, copy_to_surface) =
            surface_config(&surface, &adapter, size.width.max(1), size.height.max(1))?;
        surface.configure(&device, &config);
        let renderer = Renderer::new(
            &device,
            RendererOptions {
                surface_format: Some(config.format),
                aov: args.denoise,
                ..RendererOptions::default()
            },
        )
        .with_context(|| format!("cannot set up the tracer on {}", adapter.get_info().name))?;
        let gpu_scene = renderer.upload(&device, &queue, &scene)?;
        let (film_width, film_height) = film_size(&config, args.scale);
        let film = renderer.create_film(&device, &gpu_scene, film_width, film_height)?;
        let offscreen = offscreen_texture(&device, &config);
        if !args.quiet {
            let info = adapter.get_info();
            eprintln!(
                "viewer: {} ({:?}), surface {:?} {}x{}, {:?}, {}",
                info.name,
                info.backend,
                config.format,
                config.width,
                config.height,
                config.present_mode,
                if copy_to_surface {
                    "copied from an offscreen image"
                } else {
                    "drawn twice"
                }
            );
        }
        Ok(Self {
            window,
            surface,
            config,
            copy_to_surface,
            device,
            queue,
            renderer,
            scene: gpu_scene,
            film,
            scale: args.scale,
            offscreen,
            file_camera: scene.camera,
            scene_path: args.scene.clone(),
            inputs,
            settings_args: ViewArgsSettings {
                settings: args.settings.clone(),
                sandbox: args.sandbox,
                quiet: args.quiet,
            },
            samples_per_frame: args.samples_per_frame,
            max_samples: args.max_samples,
            frames_left: args.frames,
            screenshot: args.screenshot.clone(),
            watcher,
            in_flight: None,
            rate_mark: (Instant::now(), 0),
            mrays_per_second: 0.0,
            title_written: None,
            status: None,
            frames_drawn: 0,
            first_frame: None,
            cursor: PhysicalPosition::new(0.0, 0.0),
            drag: None,
            can_denoise: args.denoise,
            denoised: args.denoise,
        })
    }

    /// The D key: switches between the denoised and the raw film (with `--denoise`).
    fn toggle_denoise(&mut self) -> Result<()> {
        if self.can_denoise {
            self.denoised = !self.denoised;
            self.status = Some(if self.denoised { "denoised" } else { "raw" }.to_owned());
        } else {
            self.status = Some("start the viewer with --denoise to denoise".to_owned());
        }
        self.title_written = None;
        self.update_title();
        self.window.request_redraw();
        Ok(())
    }

    /// Whether another frame would add samples (or `--frames` are not done yet).
    fn wants_frames(&self) -> bool {
        self.frames_left.is_some()
            || self.film.requested_samples() < self.max_samples
            || !self.film.is_complete()
    }

    /// Draws one frame; with `--frames`, counts it and after the last one finishes
    /// the film, shows it, writes the screenshot and says so.
    fn redraw(&mut self) -> Result<Done> {
        let samples = if self.film.requested_samples() < self.max_samples {
            self.samples_per_frame
                .min(self.max_samples - self.film.requested_samples())
        } else {
            0
        };
        if !self.frame(samples)? {
            return Ok(Done::No);
        }
        let Some(left) = self.frames_left.as_mut() else {
            return Ok(Done::No);
        };
        *left -= 1;
        if *left > 0 {
            return Ok(Done::No);
        }
        self.wait_in_flight()?;
        let elapsed = self.first_frame.map(|t| t.elapsed()).unwrap_or_default();
        // Every sample asked for is traced; one more frame shows the finished film.
        self.renderer
            .finish(&self.device, &self.queue, &self.scene, &mut self.film)?;
        let mut tries = 0;
        while !self.frame(0)? {
            tries += 1;
            if tries == MAX_SKIPPED_FRAMES {
                bail!("the window's surface gave no texture to show the finished image in");
            }
        }
        self.wait_in_flight()?;
        let noise = self.noise_text()?;
        let seconds = elapsed.as_secs_f64();
        eprintln!(
            "viewer: {} frames in {seconds:.2} s: {:.2} frames/s at {}x{}, {} samples per \
             frame; {} samples per pixel, {:.1} Mrays/s, {noise}",
            self.frames_drawn - 1,
            f64::from(self.frames_drawn - 1) / seconds.max(1e-9),
            self.config.width,
            self.config.height,
            self.samples_per_frame,
            self.film.samples(),
            self.film.rays_traced() as f64 / 1e6 / seconds.max(1e-9),
        );
        if let Some(path) = self.screenshot.clone() {
            self.write_shown(&path)?;
            eprintln!("viewer: wrote {}", path.display());
        }
        Ok(Done::Yes)
    }

    /// Waits for the last frame's submission, if any.
    fn wait_in_flight(&mut self) -> Result<()> {
        if let Some(index) = self.in_flight.take() {
            self.device
                .poll(wgpu::PollType::Wait {
                    submission_index: Some(index),
                    timeout: None,
                })
                .context("the GPU device was lost")?;
        }
        Ok(())
    }

    /// Adds `samples` samples per pixel and shows the film; `false` if the surface
    /// had no texture to show it in (the frame is skipped).
    fn frame(&mut self, samples: u32) -> Result<bool> {
        self.wait_in_flight()?;
        let surface_texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(texture) => texture,
            wgpu::CurrentSurfaceTexture::Suboptimal(texture) => texture,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                bail!("the window's surface texture could not be acquired (validation error)")
            }
        };
        self.first_frame.get_or_insert_with(Instant::now);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gpu-render viewer frame"),
            });
        self.renderer.encode_samples(
            &self.device,
            &self.queue,
            &mut encoder,
            &self.scene,
            &mut self.film,
            samples,
        )?;
        if self.denoised {
            self.renderer.encode_denoise(
                &self.device,
                &self.queue,
                &mut encoder,
                &mut self.film,
                &DenoiseSettings::default(),
            )?;
        }
        let offscreen_view = self.offscreen.create_view(&Default::default());
        self.draw_into(&mut encoder, &offscreen_view)?;
        if self.copy_to_surface {
            encoder.copy_texture_to_texture(
                self.offscreen.as_image_copy(),
                surface_texture.texture.as_image_copy(),
                self.offscreen.size(),
            );
        } else {
            let view = surface_texture.texture.create_view(&Default::default());
            self.draw_into(&mut encoder, &view)?;
        }
        let index = self.queue.submit([encoder.finish()]);
        self.window.pre_present_notify();
        self.queue.present(surface_texture);
        self.in_flight = Some(index);
        self.frames_drawn += 1;
        self.update_title();
        Ok(true)
    }

    /// Records the film's draw into `view`, a texture of the surface's format.
    fn draw_into(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
    ) -> Result<()> {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gpu-render viewer draw"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations::default(),
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if self.denoised {
            self.renderer
                .draw_denoised(&mut pass, &self.scene, &self.film)?;
        } else {
            self.renderer.draw(&mut pass, &self.scene, &self.film)?;
        }
        Ok(())
    }

    /// The window title: the scene, the samples so far, Mrays/s and any status.
    fn update_title(&mut self) {
        if self
            .title_written
            .is_some_and(|t| t.elapsed() < TITLE_INTERVAL)
        {
            return;
        }
        let now = Instant::now();
        self.title_written = Some(now);
        let (since, rays_then) = self.rate_mark;
        let rays = self.film.rays_traced();
        if rays < rays_then {
            // The film restarted (camera, scene or size).
            self.rate_mark = (now, rays);
        } else if now.duration_since(since) >= RATE_INTERVAL {
            let seconds = now.duration_since(since).as_secs_f64();
            self.mrays_per_second = (rays - rays_then) as f64 / 1e6 / seconds;
            self.rate_mark = (now, rays);
        }
        let mrays = self.mrays_per_second;
        let mut title = format!(
            "{}: {} spp, {mrays:.1} Mrays/s",
            title_name(&self.scene_path),
            self.film.samples()
        );
        if let Some(status) = &self.status {
            title.push_str(" | ");
            title.push_str(status);
        }
        self.window.set_title(&title);
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        if (size.width, size.height) == (self.config.width, self.config.height) {
            return Ok(());
        }
        self.wait_in_flight()?;
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&self.device, &self.config);
        let (film_width, film_height) = film_size(&self.config, self.scale);
        self.film
            .resize(&self.device, &self.renderer, film_width, film_height)?;
        self.offscreen = offscreen_texture(&self.device, &self.config);
        self.window.request_redraw();
        Ok(())
    }

    fn cursor_moved(&mut self, position: PhysicalPosition<f64>) {
        self.cursor = position;
        let Some((drag, last)) = self.drag else {
            return;
        };
        let (dx, dy) = (position.x - last.x, position.y - last.y);
        self.drag = Some((drag, position));
        let height = self.config.height;
        match drag {
            Drag::Orbit => self.move_camera(|camera| orbit::orbit(camera, dx, dy)),
            Drag::Pan => self.move_camera(|camera| orbit::pan(camera, dx, dy, height)),
        }
    }

    fn mouse_button(&mut self, button: MouseButton, pressed: bool) {
        let drag = match button {
            MouseButton::Left => Drag::Orbit,
            MouseButton::Right | MouseButton::Middle => Drag::Pan,
            _ => return,
        };
        if pressed {
            self.drag = Some((drag, self.cursor));
        } else if self.drag.is_some_and(|(d, _)| d == drag) {
            self.drag = None;
        }
    }

    /// Moves the camera; the film restarts at its next samples. A move that would
    /// make the view undefined is ignored.
    fn move_camera(&mut self, change: impl FnOnce(&Camera) -> Camera) {
        let camera = change(self.scene.camera());
        if self.renderer.set_camera(&mut self.scene, &camera).is_ok() {
            self.window.request_redraw();
        }
    }

    /// `S`: writes what the window shows next to the scene file's name.
    fn save(&mut self) -> Result<()> {
        let path = saved_image_path(&self.scene_path, self.film.samples());
        match self.write_shown(&path) {
            Ok(()) => {
                eprintln!("viewer: wrote {}", path.display());
                self.status = Some(format!("saved {}", path.display()));
            }
            Err(error) => {
                eprintln!("error: {}", crate::describe_error(&error));
                self.status = Some(format!("cannot save: {error}"));
            }
        }
        self.title_written = None;
        self.update_title();
        Ok(())
    }

    /// `N`: shows the film's estimated noise in the title (a blocking readback of the
    /// per-pixel sums, so on demand rather than every frame).
    fn show_noise(&mut self) -> Result<()> {
        self.wait_in_flight()?;
        let noise = self.noise_text()?;
        self.status = Some(format!("{} spp: {noise}", self.film.samples()));
        self.title_written = None;
        self.update_title();
        Ok(())
    }

    /// The film's estimated noise as the CLI's summary line words it: the relative RMSE
    /// of luminance that the per-pixel standard errors predict (`docs/quality.md`).
    fn noise_text(&mut self) -> Result<String> {
        let estimate = self
            .renderer
            .read_noise(&self.device, &self.queue, &self.scene, &mut self.film)
            .context("cannot read the film's noise estimate back")?;
        Ok(match estimate.relative_error() {
            Some(relative) => format!(
                "estimated noise {:.2}% (relative RMSE of luminance)",
                relative * 100.0
            ),
            None => "estimated noise unknown (needs 2 spp and light)".to_owned(),
        })
    }

    /// Reads the offscreen image (what the window shows) back and writes it as an
    /// 8-bit RGBA PNG.
    fn write_shown(&mut self, path: &Path) -> Result<()> {
        output::check_not_read(path, &self.inputs)?;
        self.wait_in_flight()?;
        let bgra = match self.config.format {
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb => true,
            wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => false,
            other => bail!("cannot save the window's {other:?} image as an 8-bit PNG"),
        };
        let mut pixels = read_texture(&self.device, &self.queue, &self.offscreen, 4, None)
            .context("cannot read the window's image back")?;
        if bgra {
            for pixel in pixels.chunks_exact_mut(4) {
                pixel.swap(0, 2);
            }
        }
        output::write_png_rgba8(
            path,
            self.offscreen.width(),
            self.offscreen.height(),
            pixels,
        )?;
        Ok(())
    }

    /// Reloads the scene file if it changed. On an error the old scene stays and the
    /// error goes to stderr and the title.
    fn reload_if_changed(&mut self) {
        if !self.watcher.changed() {
            return;
        }
        match self.reload() {
            Ok(()) => {
                eprintln!("viewer: reloaded {}", self.scene_path.display());
                self.status = None;
            }
            Err(error) => {
                let described = crate::describe_error(&error);
                eprintln!(
                    "error: reloading {}: {described}",
                    self.scene_path.display()
                );
                let first_line = described;
                let first_line = first_line.lines().next().unwrap_or_default().to_owned();
                self.status = Some(format!("reload failed: {first_line}"));
            }
        }
        self.title_written = None;
        self.update_title();
        self.window.request_redraw();
    }

    fn reload(&mut self) -> Result<()> {
        let args = &self.settings_args;
        let Loaded {
            mut scene, inputs, ..
        } = crate::loading::load_any(
            &self.scene_path,
            &view_load_args(&args.settings, args.sandbox, args.quiet),
        )?;
        let file_camera = scene.camera;
        // The interactive camera stays unless the file's camera changed.
        if file_camera == self.file_camera {
            scene.camera = *self.scene.camera();
        }
        self.wait_in_flight()?;
        let gpu_scene = self
            .renderer
            .upload(&self.device, &self.queue, &scene)
            .map_err(|e| anyhow!(e))?;
        if gpu_scene.stack_size() > self.scene.stack_size() {
            let (film_width, film_height) = film_size(&self.config, self.scale);
            self.film =
                self.renderer
                    .create_film(&self.device, &gpu_scene, film_width, film_height)?;
        }
        self.scene = gpu_scene;
        self.file_camera = file_camera;
        self.inputs = inputs;
        Ok(())
    }
}

/// The film's size for a window of `config`'s size at `scale` (at least 1 x 1).
fn film_size(config: &wgpu::SurfaceConfiguration, scale: f64) -> (u32, u32) {
    let scaled = |n: u32| ((f64::from(n) * scale).round() as u32).max(1);
    (scaled(config.width), scaled(config.height))
}

/// The backends the viewer's instance uses.
fn viewer_backends() -> wgpu::Backends {
    wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY)
}

/// The adapter `--adapter` names among those of `backends` that can present to
/// `surface`; the error lists them.
fn choose_adapter(
    instance: &wgpu::Instance,
    backends: wgpu::Backends,
    surface: &wgpu::Surface<'_>,
    choice: &crate::args::AdapterArg,
) -> Result<wgpu::Adapter> {
    let adapters: Vec<wgpu::Adapter> = pollster::block_on(instance.enumerate_adapters(backends))
        .into_iter()
        .filter(|adapter| adapter.is_surface_supported(surface))
        .collect();
    let choice = match choice {
        crate::args::AdapterArg::Index(i) => AdapterChoice::Index(*i),
        crate::args::AdapterArg::Name(name) => AdapterChoice::NameContains(name.clone()),
        crate::args::AdapterArg::List => AdapterChoice::Default,
    };
    select_adapter(&adapters, &choice)
        .context("--adapter matches none of the adapters that can present to this window")
}

/// The surface configuration: an 8-bit format (sRGB preferred) the surface offers,
/// opaque alpha where offered, FIFO presentation (always offered); and whether the
/// surface can be copied into.
fn surface_config(
    surface: &wgpu::Surface<'_>,
    adapter: &wgpu::Adapter,
    width: u32,
    height: u32,
) -> Result<(wgpu::SurfaceConfiguration, bool)> {
    let caps = surface.get_capabilities(adapter);
    let mut config = surface
        .get_default_config(adapter, width, height)
        .context("the GPU adapter cannot present to this window's surface")?;
    let preferred = [
        wgpu::TextureFormat::Bgra8UnormSrgb,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureFormat::Rgba8Unorm,
    ];
    if let Some(format) = preferred.iter().find(|f| caps.formats.contains(f)) {
        config.format = *format;
    }
    if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
        config.alpha_mode = wgpu::CompositeAlphaMode::Opaque;
    }
    config.present_mode = wgpu::PresentMode::Fifo;
    let copy = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
    config.usage = if copy {
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    Ok((config, copy))
}

/// The offscreen image of the surface's format and size.
fn offscreen_texture(device: &wgpu::Device, config: &wgpu::SurfaceConfiguration) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("gpu-render viewer image"),
        size: wgpu::Extent3d {
            width: config.width,
            height: config.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: config.format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The scene file's name for the title.
fn title_name(path: &Path) -> String {
    path.file_name()
        .map(|name| name.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Where `S` saves: `STEM-view-Nspp.png` in the current directory.
fn saved_image_path(scene_path: &Path, samples: u32) -> PathBuf {
    let stem = scene_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    PathBuf::from(format!("{stem}-view-{samples}spp.png"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saved_images_are_named_after_the_scene_and_its_samples() {
        assert_eq!(
            saved_image_path(Path::new("scenes/showcase.toml"), 12),
            PathBuf::from("showcase-view-12spp.png")
        );
        assert_eq!(title_name(Path::new("a/b/c.toml")), "c.toml");
    }
}
