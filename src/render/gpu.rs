//! The wgpu device headless renders draw with: a real GPU when there is one, else a software rasteriser.

use std::sync::Arc;

use egui_wgpu::wgpu::{self, Adapter, Backend, DeviceType};
use egui_wgpu::{RenderState, RendererOptions, WgpuConfiguration, WgpuSetup, WgpuSetupCreateNew};

use super::RenderError;

/// A fresh render state on the best adapter. Predictable options (no MSAA, no dithering) make the same input give
/// the same bytes on one machine.
pub fn render_state() -> Result<RenderState, RenderError> {
    let mut setup = WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends.remove(wgpu::Backends::BROWSER_WEBGPU);
    setup.native_adapter_selector = Some(Arc::new(|adapters, _surface| best(adapters)));
    let setup = WgpuSetup::CreateNew(setup);
    let instance = pollster::block_on(setup.new_instance());
    let config = WgpuConfiguration { wgpu_setup: setup, ..Default::default() };
    pollster::block_on(RenderState::create(&config, &instance, None, RendererOptions::PREDICTABLE))
        .map_err(|e| RenderError::Gpu(e.to_string()))
}

/// Hardware before software, then the native API before GL; the order on one machine never changes.
fn best(adapters: &[Adapter]) -> Result<Adapter, String> {
    adapters
        .iter()
        .min_by_key(|a| rank(&a.get_info()))
        .cloned()
        .ok_or_else(|| "no graphics adapter (install Mesa's EGL and llvmpipe: libegl-mesa0 libgl1-mesa-dri)".to_owned())
}

fn rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let device = match info.device_type {
        DeviceType::DiscreteGpu => 0,
        DeviceType::IntegratedGpu => 1,
        DeviceType::VirtualGpu | DeviceType::Other => 2,
        DeviceType::Cpu => 3,
    };
    let backend = match info.backend {
        Backend::Vulkan | Backend::Metal | Backend::Dx12 => 0,
        Backend::Gl => 1,
        Backend::BrowserWebGpu | Backend::Noop => 2,
    };
    (device, backend)
}
