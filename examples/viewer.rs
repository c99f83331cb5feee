//! A windowed viewer that embeds voxsplat as a host program would: the example owns the window
//! (winit), the Vulkan instance, device, queue and swapchain (ash), and voxsplat adopts its device
//! (`Context::from_host`) and draws each frame straight into the acquired swapchain image
//! (`Renderer::render_to`), ordered by the example's semaphores. See docs/guide/embedding.md.
//!
//! It opens whatever `voxsplat render` opens (`--volume`, `--terrain`, `--scene` and their flags).
//! Mouse: left drag orbits, wheel zooms, middle drag (or ctrl + left) pans, right drag edits the
//! transfer function's window (x: level, y: width), shift + left drag moves the clip plane.
//! Keys: o order, c compositing, r raster, l levels of detail, [ ] opacity, p clip plane through the
//! centre facing the eye, m mode (composite, mip, minip, average, xray, iso), , . the isosurface's
//! value down or up, b the bounding box and a slice plane drawn through the volume by depth (the
//! host's own geometry: `viewer_mesh.rs`), 9 0 the slice plane down or up, t T the next or the
//! previous time point of a series (a 4-D NIfTI or an OME-Zarr image with a time axis, opened
//! without --time: `Renderer::update_volume` swaps each in), s save `viewer-tf.toml` and, for a
//! volume, `viewer-session.toml` (the camera, transfer function, shading, mode and options) and
//! print the `render` command that draws the frame again, q or Esc quit. The title shows the frame time and the modes. While a button is held, frames are drawn at
//! `--interactive-scale` (0.5 by default) and stretched on the device; full size when let go.
//!
//! Headless runs (CI, under Xvfb): `--frames N` draws N frames of a scripted orbit ending at the
//! command line's camera, applies `--tf-range` and `--opacity` halfway (the transfer-function
//! editor's path), saves the last frame read back from the swapchain image with `--screenshot`, and
//! exits; `--validation` fails the run on any validation message.
use clap::Parser;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::ffi::c_void;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;
use voxsplat::glam::{Vec3, Vec4};
use voxsplat::vk::ash::{self, vk};
use voxsplat::vk::{Context, HostHandles, HostTarget, Semaphore};
use voxsplat::{
    options::Clip, options::Composite, options::Lod, options::Raster, order::OrderKind, Camera, Error, RenderOptions,
    Renderer, Result,
};
use voxsplat_cli::open::{camera_of, open, parse_background, SceneArgs};
use voxsplat_cli::view::{Orbit, COMPOSITES, ORDERS, RASTERS};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

#[path = "viewer_mesh.rs"]
mod mesh;

#[derive(Parser)]
#[command(name = "viewer", about = "voxsplat in a window: orbit, zoom, pan, modes, transfer function, clip plane")]
struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Draw this many frames of a scripted orbit (ending at the command line's camera), then exit.
    #[arg(long)]
    frames: Option<u32>,
    /// The scripted orbit's sweep in degrees about the vertical axis.
    #[arg(long, default_value = "90")]
    orbit: f32,
    /// Scripted transfer-function edit halfway through --frames: the raw values mapped to 0 and 1.
    #[arg(long, value_parser = voxsplat_cli::open::parse_floats::<2>, allow_hyphen_values = true)]
    tf_range: Option<[f32; 2]>,
    /// Scripted edit: opacity scale.
    #[arg(long, default_value = "1")]
    opacity: f32,
    /// Scripted key presses, one per frame from the first (e.g. "crlp"): the keyboard's path.
    #[arg(long, default_value = "")]
    keys: String,
    /// Save the last frame, read back from the swapchain image, as a PNG.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Save the transfer function in use at exit (TOML, for `voxsplat render --tf`).
    #[arg(long)]
    save_tf: Option<PathBuf>,
    /// Save the session at exit: the last frame's camera, the transfer function, shading, mode
    /// and options, which `voxsplat render --volume FILE --session S --size WxH` draws again.
    #[arg(long)]
    save_session: Option<PathBuf>,
    /// The window's background, R,G,B[,A].
    #[arg(long, value_parser = parse_background, default_value = "0,0,0")]
    background: [f32; 4],
    #[arg(long, default_value = "splat", value_parser = ["splat", "sheet", "slab"])]
    composite: String,
    #[arg(long, default_value = "auto")]
    raster: String,
    /// Levels of detail (as `render --lod`; `l` toggles them).
    #[arg(long, default_value = "auto", value_parser = ["off", "auto"])]
    lod: String,
    /// The reconstruction kernel (as `voxsplat-lab render --kernel`).
    #[arg(long, default_value = "crawfis-max")]
    kernel: String,
    /// Draw on a grid this fraction of the window's size, stretched by the device's blit.
    #[arg(long, default_value = "1")]
    render_scale: f32,
    /// While a mouse button is held (orbit, pan, window/level, clip), draw at this scale at most:
    /// interactive frames at a fraction of the cost, full detail when the mouse is let go. 1: off.
    #[arg(long, default_value = "0.5")]
    interactive_scale: f32,
    /// Swapchain present mode: fifo (vsync) or immediate/mailbox when the surface has them.
    #[arg(long, default_value = "fifo", value_parser = ["fifo", "mailbox", "immediate"])]
    present: String,
    /// Prefer a UNORM swapchain format over an sRGB one.
    #[arg(long)]
    unorm: bool,
    /// Start with the bounding box and slice plane drawn through the volume (`b` toggles them).
    /// They are drawn at full size: the render scales do not apply while they show.
    #[arg(long)]
    mesh: bool,
    /// Where the slice plane lies along the grid's k axis, 0 to 1.
    #[arg(long, default_value = "0.5")]
    slice: f32,
}

static MESSAGES: AtomicU64 = AtomicU64::new(0);

unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _: *mut c_void,
) -> vk::Bool32 {
    MESSAGES.fetch_add(1, Ordering::Relaxed);
    // SAFETY: the layer passes a valid callback data pointer whose message is a C string.
    let text = unsafe { (*data).message_as_c_str() }.map(|m| m.to_string_lossy().into_owned()).unwrap_or_default();
    eprintln!("validation ({severity:?}): {text}");
    vk::FALSE
}

fn vk_err(call: &'static str) -> impl Fn(vk::Result) -> Error {
    move |e| Error::Unsupported(format!("{call}: {e}"))
}

/// The example's Vulkan objects: what a host program already has.
struct Host {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    surface_fn: ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    family: u32,
    swapchain_fn: ash::khr::swapchain::Device,
    large_points: bool,
    int64_atomics: bool,
}

impl Host {
    fn new(window: &Window, validation: bool) -> Result<Self> {
        let display = window.display_handle().map_err(|e| Error::Unsupported(e.to_string()))?.as_raw();
        let handle = window.window_handle().map_err(|e| Error::Unsupported(e.to_string()))?.as_raw();
        // SAFETY: the system loader; it lives as long as `entry`.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        let mut extensions =
            ash_window::enumerate_required_extensions(display).map_err(vk_err("surface extensions"))?.to_vec();
        let mut layers = Vec::new();
        if validation {
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
            layers.push(c"VK_LAYER_KHRONOS_validation".as_ptr());
        }
        let app = vk::ApplicationInfo::default().application_name(c"voxsplat viewer").api_version(vk::API_VERSION_1_2);
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if validation {
            info = info.push_next(&mut features);
        }
        // SAFETY: every pointer in `info` outlives the call.
        let instance = unsafe { entry.create_instance(&info, None) }.map_err(vk_err("vkCreateInstance"))?;
        let debug = if validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(on_message));
            // SAFETY: the callback is a plain function; destroyed in Drop before the instance.
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .map_err(vk_err("vkCreateDebugUtilsMessengerEXT"))?;
            Some((loader, messenger))
        } else {
            None
        };
        // SAFETY: the window outlives the surface (the app drops the host before the window).
        let surface = unsafe { ash_window::create_surface(&entry, &instance, display, handle, None) }
            .map_err(vk_err("vkCreate*SurfaceKHR"))?;
        let surface_fn = ash::khr::surface::Instance::new(&entry, &instance);
        // A device with a graphics + compute queue that presents to the surface.
        // SAFETY: plain enumeration and queries below.
        let physicals =
            unsafe { instance.enumerate_physical_devices() }.map_err(vk_err("vkEnumeratePhysicalDevices"))?;
        let mut pick = None;
        for &p in &physicals {
            let families = unsafe { instance.get_physical_device_queue_family_properties(p) };
            for (i, f) in families.iter().enumerate() {
                let flags = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
                let presents =
                    unsafe { surface_fn.get_physical_device_surface_support(p, i as u32, surface) }.unwrap_or(false);
                if f.queue_flags.contains(flags) && presents && pick.is_none() {
                    pick = Some((p, i as u32));
                }
            }
        }
        let (physical, family) = pick.ok_or_else(|| Error::Unsupported("no device presents to this window".into()))?;
        // What voxsplat needs (Vulkan 1.2 shaderOutputLayer) and what it uses when there.
        let mut has12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut has = vk::PhysicalDeviceFeatures2::default().push_next(&mut has12);
        unsafe { instance.get_physical_device_features2(physical, &mut has) };
        let large_points = has.features.large_points == vk::TRUE;
        let int64_atomics = has.features.shader_int64 == vk::TRUE && has12.shader_buffer_int64_atomics == vk::TRUE;
        if has12.shader_output_layer != vk::TRUE {
            return Err(Error::Unsupported("voxsplat needs shaderOutputLayer".into()));
        }
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .shader_output_layer(true)
            .shader_buffer_int64_atomics(int64_atomics);
        let core = vk::PhysicalDeviceFeatures::default().large_points(large_points).shader_int64(int64_atomics);
        let priorities = [1.0f32];
        let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        let device_extensions = [ash::khr::swapchain::NAME.as_ptr()];
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&device_extensions)
            .enabled_features(&core)
            .push_next(&mut f12);
        // SAFETY: the features were checked above.
        let device = unsafe { instance.create_device(physical, &info, None) }.map_err(vk_err("vkCreateDevice"))?;
        let queue = unsafe { device.get_device_queue(family, 0) };
        let swapchain_fn = ash::khr::swapchain::Device::new(&instance, &device);
        Ok(Self {
            entry,
            instance,
            debug,
            surface_fn,
            surface,
            physical,
            device,
            queue,
            family,
            swapchain_fn,
            large_points,
            int64_atomics,
        })
    }

    fn handles(&self) -> HostHandles {
        HostHandles {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical: self.physical,
            device: self.device.clone(),
            queue: self.queue,
            queue_family: self.family,
            large_points: self.large_points,
            int64_atomics: self.int64_atomics,
        }
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // SAFETY: the swapchain, voxsplat's renderer and semaphores are gone (dropped first).
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_device(None);
            self.surface_fn.destroy_surface(self.surface, None);
            if let Some((loader, messenger)) = &self.debug {
                loader.destroy_debug_utils_messenger(*messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// The swapchain and one "rendered" semaphore per image.
struct Swapchain {
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    format: vk::Format,
    extent: vk::Extent2D,
    done: Vec<Semaphore>,
}

impl Swapchain {
    fn new(host: &Host, ctx: &Arc<Context>, size: (u32, u32), args: &Args, old: vk::SwapchainKHR) -> Result<Self> {
        let (phys, surface) = (host.physical, host.surface);
        // SAFETY: plain surface queries.
        let caps = unsafe { host.surface_fn.get_physical_device_surface_capabilities(phys, surface) }
            .map_err(vk_err("surface capabilities"))?;
        let formats = unsafe { host.surface_fn.get_physical_device_surface_formats(phys, surface) }
            .map_err(vk_err("surface formats"))?;
        let modes = unsafe { host.surface_fn.get_physical_device_surface_present_modes(phys, surface) }
            .map_err(vk_err("present modes"))?;
        let mut wanted = [
            vk::Format::B8G8R8A8_SRGB,
            vk::Format::R8G8B8A8_SRGB,
            vk::Format::B8G8R8A8_UNORM,
            vk::Format::R8G8B8A8_UNORM,
        ];
        if args.unorm {
            wanted.rotate_left(2);
        }
        let chosen = wanted
            .iter()
            .find_map(|w| formats.iter().find(|f| f.format == *w))
            .ok_or_else(|| Error::Unsupported(format!("no swapchain format voxsplat writes among {formats:?}")))?;
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(Error::Unsupported("the surface's images cannot be transfer destinations and sources".into()));
        }
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D { width: size.0, height: size.1 }
        };
        let mode = match args.present.as_str() {
            "mailbox" => vk::PresentModeKHR::MAILBOX,
            "immediate" => vk::PresentModeKHR::IMMEDIATE,
            _ => vk::PresentModeKHR::FIFO,
        };
        let mode = if modes.contains(&mode) { mode } else { vk::PresentModeKHR::FIFO };
        let count = if caps.max_image_count > 0 {
            (caps.min_image_count + 1).min(caps.max_image_count)
        } else {
            caps.min_image_count + 1
        };
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface)
            .min_image_count(count)
            .image_format(chosen.format)
            .image_color_space(chosen.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(mode)
            .clipped(true)
            .old_swapchain(old);
        // SAFETY: checked capabilities; `old` is retired by this call and destroyed by the caller.
        let raw = unsafe { host.swapchain_fn.create_swapchain(&info, None) }.map_err(vk_err("vkCreateSwapchainKHR"))?;
        let images = unsafe { host.swapchain_fn.get_swapchain_images(raw) }.map_err(vk_err("swapchain images"))?;
        let done = images.iter().map(|_| Semaphore::new(ctx)).collect::<Result<Vec<_>>>()?;
        Ok(Self { raw, images, format: chosen.format, extent, done })
    }

    fn destroy(self, host: &Host) {
        // SAFETY: the device is idle (Semaphore's drop waited); nothing uses the swapchain.
        drop(self.done);
        unsafe {
            let _ = host.device.device_wait_idle();
            host.swapchain_fn.destroy_swapchain(self.raw, None);
        }
    }
}

/// The isosurface's first value (normalised) and a key's step.
const ISO_START: f32 = 0.3;
const ISO_STEP: f32 = 0.02;

struct Viewer {
    args: Args,
    window: Option<Arc<Window>>,
    // Dropped in this order: voxsplat's objects, then the swapchain, then the host's device.
    acquire: Option<Semaphore>,
    mesh_pass: Option<mesh::MeshPass>,
    swapchain: Option<Swapchain>,
    renderer: Option<Renderer>,
    host: Option<Host>,
    base: Option<Camera>,
    grid: Option<voxsplat::volume::Grid>,
    mesh: bool,
    slice: f32,
    radius: f32,
    view: Orbit,
    options: RenderOptions,
    indices: [usize; 3],
    tf: Option<voxsplat::classify::TransferFunction>,
    raw_range: (f32, f32),
    /// A series' time points, and the one shown.
    series: Option<(voxsplat_cli::series::Series, u32)>,
    clip_offset: Option<(Vec3, f32)>,
    frame: u32,
    times: Vec<f64>,
    mouse: (f64, f64),
    buttons: [bool; 3],
    modifiers: ModifiersState,
    message: String,
    resized: bool,
    failure: Option<Error>,
}

impl Viewer {
    fn new(args: Args) -> Result<Self> {
        let mut options = RenderOptions::default();
        options.background = Some(args.background);
        options.composite = args.composite.parse::<Composite>()?;
        options.raster = args.raster.parse::<Raster>()?;
        options.lod = args.lod.parse::<Lod>()?;
        options.order = args.scene.research.order.parse::<OrderKind>()?;
        options.render_scale = args.render_scale;
        options.kernel = args.kernel.parse()?;
        voxsplat::low_level::check_scale(args.interactive_scale)?;
        options.validate()?;
        let indices = [
            ORDERS.iter().position(|o| *o == args.scene.research.order).unwrap_or(0),
            COMPOSITES.iter().position(|c| *c == args.composite).unwrap_or(0),
            RASTERS.iter().position(|r| *r == args.raster).unwrap_or(0),
        ];
        let (mesh, slice) = (args.mesh, args.slice.clamp(0.0, 1.0));
        Ok(Self {
            args,
            window: None,
            acquire: None,
            mesh_pass: None,
            swapchain: None,
            renderer: None,
            host: None,
            base: None,
            grid: None,
            mesh,
            slice,
            radius: 1.0,
            view: Orbit::HOME,
            options,
            indices,
            tf: None,
            raw_range: (0.0, 1.0),
            series: None,
            clip_offset: None,
            frame: 0,
            times: Vec::new(),
            mouse: (0.0, 0.0),
            buttons: [false; 3],
            modifiers: ModifiersState::empty(),
            message: String::new(),
            resized: false,
            failure: None,
        })
    }

    /// Window, device, voxsplat on that device, the scene, the swapchain.
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let (w, h) = self.args.scene.size;
        let attributes =
            Window::default_attributes().with_title("voxsplat").with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| Error::Unsupported(e.to_string()))?);
        let host = Host::new(&window, self.args.scene.validation)?;
        // SAFETY: the host's objects are valid, belong together, and outlive the renderer (dropped
        // first); the queue is used from this thread only, never while voxsplat submits.
        let ctx = unsafe { Context::from_host(host.handles()) }?;
        let mut renderer = Renderer::with_context(ctx.clone())?;
        let a = &self.args.scene;
        let series = a.volume.as_ref().filter(|_| a.time.is_none()).map(|p| voxsplat::loaders::time_points(p));
        let (bricked, set, content) = if series.transpose()?.is_some_and(|t| t > 1) {
            // A series: its first time point, normalised by the whole series' range.
            let s = voxsplat_cli::series::Series::open(a)?;
            let scene = s.scene(a, 0)?;
            let content = voxsplat_cli::open::Content { orientation: s.orientation(), bounds: scene.visible_bounds() };
            let set = voxsplat::SplatSet::empty(scene.store.grid()?)?;
            self.series = Some((s, 0));
            (Some(scene), set, content)
        } else {
            open(a, self.options.order != OrderKind::Pbtf)?
        };
        let grid = *set.grid();
        match bricked {
            Some(b) => {
                self.raw_range = b.store.range;
                self.tf = Some(b.transfer_function().clone());
                renderer.set_bricks(b)?;
            }
            None => renderer.set_scene(set)?,
        }
        self.base = Some(camera_of(&self.args.scene, &grid, &content)?);
        self.grid = Some(grid);
        self.radius = 0.5 * grid.diagonal() + 4.0 * grid.kernel_spacing();
        let size = window.inner_size();
        self.swapchain =
            Some(Swapchain::new(&host, &ctx, (size.width, size.height), &self.args, vk::SwapchainKHR::null())?);
        self.acquire = Some(Semaphore::new(&ctx)?);
        self.renderer = Some(renderer);
        self.host = Some(host);
        self.window = Some(window);
        Ok(())
    }

    fn recreate_swapchain(&mut self) -> Result<()> {
        let (Some(host), Some(window), Some(renderer)) = (&self.host, &self.window, &self.renderer) else {
            return Ok(());
        };
        let ctx = renderer.context().ok_or_else(|| Error::Unsupported("no device".into()))?.clone();
        let size = window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        let old = self.swapchain.take();
        let old_raw = old.as_ref().map(|s| s.raw).unwrap_or_default();
        let new = Swapchain::new(host, &ctx, (size.width, size.height), &self.args, old_raw)?;
        if let Some(old) = old {
            old.destroy(host);
        }
        self.swapchain = Some(new);
        Ok(())
    }

    /// The scripted run: orbit to the command line's camera; the transfer-function edit halfway.
    fn script(&mut self) -> Result<()> {
        if let Some(key) = self.args.keys.chars().nth(self.frame as usize) {
            self.press(&key.to_string())?;
            eprintln!("frame {}: key {key} {}", self.frame, self.message);
        }
        let Some(n) = self.args.frames else { return Ok(()) };
        let left = n.saturating_sub(self.frame + 1) as f32 / n.max(1) as f32;
        self.view.yaw = (self.args.orbit * left).to_radians();
        if self.frame == n / 2 {
            if let Some([lo, hi]) = self.args.tf_range {
                self.edit_tf(Some((lo, hi)), self.args.opacity)?;
            } else if self.args.opacity != 1.0 {
                self.edit_tf(None, self.args.opacity)?;
            }
        }
        Ok(())
    }

    /// The transfer-function editor: a new window of raw values and an opacity scale, written to the
    /// bricked volume's table (no re-extraction).
    fn edit_tf(&mut self, range: Option<(f32, f32)>, opacity: f32) -> Result<()> {
        let (Some(tf), Some(renderer)) = (&mut self.tf, &mut self.renderer) else {
            self.message = "transfer-function edits need a bricked --volume".into();
            return Ok(());
        };
        if let Some((lo, hi)) = range {
            if hi > lo {
                tf.range = Some((lo, hi));
            }
        }
        for p in &mut tf.points {
            p.1[3] = (p.1[3] * opacity).clamp(0.0, 1.0);
        }
        tf.validate()?;
        // The volume keeps the shading it was opened with.
        let shading = renderer.volume().and_then(|v| v.shading());
        renderer.set_transfer_function(tf, shading)
    }

    /// The session of the last frame drawn (`--save-session`): what `render --session` needs to
    /// draw it again. A clip plane and the host's mesh are not part of a session: refused.
    fn session(&self) -> Result<voxsplat_cli::session::Session> {
        if self.clip_offset.is_some() || self.mesh {
            return Err(Error::InvalidArgument(
                "--save-session: a session holds no clip plane or host mesh; turn them off (p, b) first".into(),
            ));
        }
        let (Some(cam), Some(volume)) = (self.camera(), self.renderer.as_ref().and_then(|r| r.volume())) else {
            return Err(Error::InvalidArgument("--save-session needs a bricked --volume, drawn".into()));
        };
        let o = &self.options;
        let lod = match o.lod {
            Lod::Off => "off",
            _ => "auto",
        };
        Ok(voxsplat_cli::session::Session {
            mode: o.mode.to_string(),
            iso: o.iso,
            order: ORDERS[self.indices[0]].into(),
            composite: COMPOSITES[self.indices[1]].into(),
            raster: RASTERS[self.indices[2]].into(),
            lod: lod.into(),
            kernel: self.args.kernel.clone(),
            background: o.background.unwrap_or([0.0; 4]),
            clip: Vec::new(),
            crop: None,
            camera: voxsplat_cli::session::Session::view_of(&cam),
            light: voxsplat_cli::session::Session::light_of(volume.shading()),
            tf: volume.transfer_function().clone(),
        })
    }

    fn camera(&self) -> Option<Camera> {
        let sc = self.swapchain.as_ref()?;
        let base = self.base.as_ref()?;
        // The near plane follows the scene's depth, which a pan or a --target moves off the axis.
        let centre = self.grid.as_ref().map_or(base.target, |g| g.center());
        Some(self.view.camera(base, centre, self.radius, (sc.extent.width, sc.extent.height)))
    }

    /// One frame: acquire, render_to the swapchain image, (screenshot,) present.
    fn draw(&mut self) -> Result<()> {
        if self.resized {
            self.resized = false;
            self.recreate_swapchain()?;
        }
        self.script()?;
        let Some(cam) = self.camera() else { return Ok(()) };
        let (host, sc, acquire) = match (&self.host, &self.swapchain, &self.acquire) {
            (Some(h), Some(s), Some(a)) => (h, s, a),
            _ => return Ok(()),
        };
        // SAFETY: the swapchain and semaphore are valid; the semaphore is unsignalled (the last
        // frame's render_to waited for the work that waited on it).
        let acquired =
            unsafe { host.swapchain_fn.acquire_next_image(sc.raw, u64::MAX, acquire.raw(), vk::Fence::null()) };
        let index = match acquired {
            Ok((i, _)) => i as usize,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.resized = true;
                return Ok(());
            }
            Err(e) => return Err(vk_err("vkAcquireNextImageKHR")(e)),
        };
        let done = sc.done[index].raw();
        let size = (sc.extent.width, sc.extent.height);
        // The image's layout and what the frame waits on: the acquire, or with the mesh the pass
        // that drew it (its colour into the swapchain image and its depth, after the acquire).
        let (first, wait) = if self.mesh {
            if self.mesh_pass.as_ref().is_none_or(|p| p.size != size) {
                self.mesh_pass = None;
                let ctx = self.renderer.as_ref().and_then(|r| r.context()).expect("started").clone();
                // SAFETY: the host's own instance, device and queue family, which voxsplat adopted.
                self.mesh_pass = Some(unsafe {
                    mesh::MeshPass::new(&host.instance, host.physical, &host.device, host.family, &ctx, size)
                }?);
            }
            let pass = self.mesh_pass.as_ref().expect("made above");
            let grid = self.grid.as_ref().expect("started");
            let bgra = matches!(sc.format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM);
            let (color, depth) = mesh::draw(&cam, grid, self.slice, self.args.background, bgra);
            // SAFETY: the acquired image has TRANSFER_DST usage; the pass's last work completed with
            // the last frame's render_to; this thread alone uses the queue.
            unsafe { pass.submit(host.queue, sc.images[index], acquire.raw(), &color, &depth) }?;
            (vk::ImageLayout::TRANSFER_SRC_OPTIMAL, pass.drawn.raw())
        } else {
            (vk::ImageLayout::UNDEFINED, acquire.raw())
        };
        // SAFETY: a swapchain image of this device, with TRANSFER_DST and TRANSFER_SRC usage, in
        // `first` (undefined after the acquire, or holding the mesh pass's drawing); the semaphores
        // are the example's, alive across the call.
        let mut target = unsafe {
            HostTarget::new(
                sc.images[index],
                sc.format,
                size,
                (first, vk::ImageLayout::PRESENT_SRC_KHR),
                &[wait],
                &[done],
            )
        }?;
        if let (true, Some(pass)) = (self.mesh, &self.mesh_pass) {
            // SAFETY: the pass left its depth image (TRANSFER_SRC usage) and the swapchain image in
            // TRANSFER_SRC_OPTIMAL, ordered by the semaphore the frame waits on and submitted
            // before voxsplat's work on this queue.
            target = unsafe {
                target
                    .with_depth(
                        pass.depth_image(),
                        vk::Format::D32_SFLOAT,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        cam.proj(),
                    )?
                    .over()
            }?;
        }
        let renderer = self.renderer.as_mut().expect("started");
        let mut options = self.options.clone();
        if self.buttons.iter().any(|&b| b) {
            options.render_scale = options.render_scale.min(self.args.interactive_scale);
        }
        if self.mesh {
            // The host's image is the background, read pixel for pixel.
            (options.background, options.render_scale) = (None, 1.0);
        }
        let t = Instant::now();
        let mut result = renderer.render_to(&cam, &options, &target);
        if let Err(e) = &result {
            // A mode this scene cannot draw: say so, go back to the defaults, and still fill the image
            // the acquire handed over (its semaphore must be waited on).
            self.message = e.to_string();
            eprintln!("frame {}: {}; back to the default modes", self.frame, self.message);
            let mut fallback = RenderOptions::default();
            (fallback.background, fallback.clip, fallback.render_scale) =
                (self.options.background, self.options.clip, self.options.render_scale);
            self.options = fallback;
            self.indices = [0; 3];
            let mut again = fallback_or(&self.options, options.render_scale);
            again.background = options.background;
            result = renderer.render_to(&cam, &again, &target);
        }
        result?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        self.times.push(ms);
        let last = self.args.frames.is_some_and(|n| self.frame + 1 >= n);
        if last {
            if let Some(path) = &self.args.screenshot {
                save_png(&renderer.read_target(&target)?, &target, path)?;
            }
        }
        let swapchains = [sc.raw];
        let indices = [index as u32];
        let waits = [done];
        let present =
            vk::PresentInfoKHR::default().wait_semaphores(&waits).swapchains(&swapchains).image_indices(&indices);
        // SAFETY: this thread alone uses the queue between voxsplat's submissions.
        match unsafe { host.swapchain_fn.queue_present(host.queue, &present) } {
            Ok(false) => {}
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.resized = true,
            Err(e) => return Err(vk_err("vkQueuePresentKHR")(e)),
        }
        self.frame += 1;
        self.title(ms);
        Ok(())
    }

    fn title(&self, ms: f64) {
        let Some(window) = &self.window else { return };
        let o = &self.options;
        let clip = format!(
            "{}{}",
            if self.clip_offset.is_some() { ", clipped" } else { "" },
            if self.mesh { ", box and slice" } else { "" }
        );
        let mode = match o.iso {
            Some(v) => format!(", iso {v:.2}"),
            None if o.mode != voxsplat::options::Mode::Composite => format!(", {}", o.mode),
            None => String::new(),
        };
        let time = match &self.series {
            Some((s, at)) => format!(", t {at}/{}", s.times - 1),
            None => String::new(),
        };
        window.set_title(&format!(
            "voxsplat: {ms:.1} ms ({:.1} fps){time}{mode}, {}, {:?}, {}, lod {:?}{clip} {}",
            1e3 / ms.max(1e-3),
            ORDERS[self.indices[0]],
            o.composite,
            o.raster,
            o.lod,
            self.message
        ));
    }

    fn key(&mut self, key: &Key, event_loop: &ActiveEventLoop) -> Result<()> {
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) if c.as_str() == "q" => event_loop.exit(),
            Key::Character(c) => self.press(c.as_str())?,
            _ => {}
        }
        Ok(())
    }

    /// What a key does (besides quitting).
    fn press(&mut self, key: &str) -> Result<()> {
        self.message.clear();
        match key {
            "o" => {
                self.indices[0] = (self.indices[0] + 1) % ORDERS.len();
                self.options.order = ORDERS[self.indices[0]].parse()?;
            }
            "c" => {
                self.indices[1] = (self.indices[1] + 1) % COMPOSITES.len();
                self.options.composite = COMPOSITES[self.indices[1]].parse()?;
            }
            "r" => {
                self.indices[2] = (self.indices[2] + 1) % RASTERS.len();
                self.options.raster = RASTERS[self.indices[2]].parse()?;
            }
            "l" => self.options.lod = if self.options.lod == Lod::Off { Lod::Auto } else { Lod::Off },
            "m" => {
                let modes = voxsplat::options::Mode::ALL;
                let at = modes.iter().position(|&m| m == self.options.mode).unwrap_or(0);
                self.options.mode = modes[(at + 1) % modes.len()];
                self.options.iso = (self.options.mode == voxsplat::options::Mode::Iso).then_some(ISO_START);
            }
            "," | "." => match self.options.iso {
                Some(v) => {
                    let step = if key == "." { ISO_STEP } else { -ISO_STEP };
                    self.options.iso = Some((v + step).clamp(0.0, 1.0));
                }
                None => self.message = "the isosurface's value: m to --mode iso first".into(),
            },
            "[" => self.edit_tf(None, 0.8)?,
            "]" => self.edit_tf(None, 1.25)?,
            "p" => {
                self.clip_offset = match self.clip_offset {
                    Some(_) => None,
                    None => self.camera().map(|c| (c.forward(), 0.0)),
                };
                self.update_clip()?;
            }
            "b" => self.mesh = !self.mesh,
            "9" | "0" => {
                let step = if key == "0" { 1.0 / 32.0 } else { -1.0 / 32.0 };
                self.slice = (self.slice + step).clamp(0.0, 1.0);
                if !self.mesh {
                    self.message = "the slice plane: b to show it first".into();
                }
            }
            "t" | "T" => match (&mut self.series, &mut self.renderer) {
                (Some((series, at)), Some(renderer)) => {
                    let n = series.times;
                    *at = if key == "t" { (*at + 1) % n } else { (*at + n - 1) % n };
                    let u = renderer.update_volume(series.store(*at)?)?;
                    self.message = format!("time point {} of 0..{}, {} bricks changed", *at, n - 1, u.changed);
                }
                _ => self.message = "time points: open a 4-D NIfTI or an OME-Zarr image with a time axis".into(),
            },
            "s" => self.save()?,
            _ => {}
        }
        Ok(())
    }

    /// The clip plane: through the scene's centre (moved by the drag), keeping what lies beyond it.
    fn update_clip(&mut self) -> Result<()> {
        self.options.clip = match (self.clip_offset, &self.base) {
            (Some((n, offset)), Some(base)) => {
                let d = -n.dot(base.target) - offset;
                Clip::new(&[Vec4::new(n.x, n.y, n.z, d)], None)?
            }
            _ => Clip::default(),
        };
        Ok(())
    }

    fn save(&mut self) -> Result<()> {
        if let Some(tf) = &self.tf {
            std::fs::write("viewer-tf.toml", tf.to_toml()?)
                .map_err(|e| Error::Io { path: "viewer-tf.toml".into(), source: e })?;
        }
        // A bricked volume: the session, which draws this frame again.
        if let (Ok(session), Some(volume), Some(cam)) = (self.session(), &self.args.scene.volume, self.camera()) {
            session.save(std::path::Path::new("viewer-session.toml"))?;
            println!(
                "voxsplat render --volume {} --session viewer-session.toml --size {}x{}",
                volume.display(),
                cam.width,
                cam.height
            );
            self.message = "saved viewer-session.toml and viewer-tf.toml".into();
            return Ok(());
        }
        if let Some(cam) = self.camera() {
            let v = |p: Vec3| format!("{},{},{}", p.x, p.y, p.z);
            println!(
                "voxsplat render --eye {} --target {} --up {} --near {} --far {} --size {}x{}{}",
                v(cam.eye),
                v(cam.target),
                v(cam.up),
                cam.near,
                cam.far,
                cam.width,
                cam.height,
                if self.tf.is_some() { " --tf viewer-tf.toml" } else { "" }
            );
        }
        self.message = "saved viewer-tf.toml".into();
        Ok(())
    }

    fn mouse_moved(&mut self, x: f64, y: f64) -> Result<()> {
        let (dx, dy) = ((x - self.mouse.0) as f32, (y - self.mouse.1) as f32);
        self.mouse = (x, y);
        let [left, middle, right] = self.buttons;
        let shift = self.modifiers.shift_key();
        let ctrl = self.modifiers.control_key();
        let (width, height) =
            self.swapchain.as_ref().map(|s| (s.extent.width as f32, s.extent.height as f32)).unwrap_or((1.0, 1.0));
        if left && shift {
            if let Some((n, offset)) = self.clip_offset {
                self.clip_offset = Some((n, offset + dy / height * 2.0 * self.radius));
                self.update_clip()?;
            }
        } else if middle || (left && ctrl) {
            if let Some(base) = &self.base {
                self.view.slide(base, self.radius, dx, dy, height);
            }
        } else if left {
            self.view.turn(dx, dy, width, height);
        } else if right {
            let (lo, hi) = self.raw_range;
            let span = hi - lo;
            let tf = self.tf.as_ref().map(|t| t.range.unwrap_or(self.raw_range));
            if let Some((a, b)) = tf {
                let (level, window) =
                    (0.5 * (a + b) + dx / width * span, ((b - a) * (1.0 + dy / height)).max(span * 1e-3));
                self.edit_tf(Some((level - 0.5 * window, level + 0.5 * window)), 1.0)?;
            }
        } else {
            // No button held: the value under the cursor (Renderer::pick), shown in the title.
            if let (Some(cam), Some(r)) = (self.camera(), self.renderer.as_mut()) {
                self.message = match r.pick(&cam, &self.options, x as f32, y as f32) {
                    Ok(Some(p)) => {
                        format!("| value {:.3} at voxel {} {} {}", p.value, p.voxel[0], p.voxel[1], p.voxel[2])
                    }
                    Ok(None) | Err(_) => String::new(),
                };
                self.title(self.times.last().copied().unwrap_or(0.0));
            }
        }
        Ok(())
    }
}

/// `options` at `scale`.
fn fallback_or(options: &RenderOptions, scale: f32) -> RenderOptions {
    let mut o = options.clone();
    o.render_scale = scale;
    o
}

/// A PNG of a swapchain image's texels: its bytes are already the display values (sRGB formats
/// store the encoded value, UNORM ones the value voxsplat wrote).
fn save_png(texels: &[u8], target: &HostTarget, path: &std::path::Path) -> Result<()> {
    let (w, h) = target.size();
    let format = voxsplat::vk::vk_format(target.format());
    let bgra = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM);
    let rgba: Vec<u8> = texels
        .chunks_exact(4)
        .flat_map(|t| if bgra { [t[2], t[1], t[0], t[3]] } else { [t[0], t[1], t[2], t[3]] })
        .collect();
    let img =
        image::RgbaImage::from_raw(w, h, rgba).ok_or_else(|| Error::InvalidArgument("short screenshot".into()))?;
    img.save(path).map_err(|e| Error::Image { path: path.display().to_string(), message: e.to_string() })
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            if let Err(e) = self.start(event_loop) {
                self.failure = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(_) => {
                self.resized = true;
                Ok(())
            }
            WindowEvent::ModifiersChanged(m) => {
                self.modifiers = m.state();
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                self.key(&event.logical_key, event_loop)
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let i = match button {
                    MouseButton::Left => 0,
                    MouseButton::Middle => 1,
                    MouseButton::Right => 2,
                    _ => return,
                };
                self.buttons[i] = state == ElementState::Pressed;
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => self.mouse_moved(position.x, position.y),
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.view.wheel(lines);
                Ok(())
            }
            WindowEvent::RedrawRequested => {
                let r = self.draw();
                if self.args.frames.is_some_and(|n| self.frame >= n) {
                    event_loop.exit();
                }
                r
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.failure = Some(e);
            event_loop.exit();
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

fn run(args: Args) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| Error::Unsupported(format!("no window system: {e}")))?;
    let save_tf = args.save_tf.clone();
    let mut viewer = Viewer::new(args)?;
    event_loop.run_app(&mut viewer).map_err(|e| Error::Unsupported(e.to_string()))?;
    if let Some(e) = viewer.failure.take() {
        return Err(e);
    }
    if let (Some(path), Some(tf)) = (save_tf, &viewer.tf) {
        std::fs::write(&path, tf.to_toml()?).map_err(|e| Error::Io { path: path.display().to_string(), source: e })?;
    }
    if let Some(path) = &viewer.args.save_session {
        viewer.session()?.save(path)?;
    }
    let mut times = viewer.times.clone();
    if !times.is_empty() {
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        println!("{} frames, median {median:.2} ms per frame ({:.1} fps)", times.len(), 1e3 / median);
    }
    // voxsplat's objects go before the host's device.
    viewer.acquire = None;
    viewer.mesh_pass = None;
    let host = viewer.host.take();
    if let (Some(sc), Some(h)) = (viewer.swapchain.take(), &host) {
        sc.destroy(h);
    }
    viewer.renderer = None;
    drop(host);
    let n = MESSAGES.load(Ordering::Relaxed);
    if n > 0 {
        return Err(Error::Unsupported(format!("{n} validation message(s)")));
    }
    Ok(())
}

fn main() -> std::process::ExitCode {
    match run(Args::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("viewer: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
