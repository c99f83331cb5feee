//! Validation-layer messages are counted and kept, never printed or aborted on: an embedded
//! library must surface them to its host (tests fail on any).
use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// What the debug messenger has seen.
#[derive(Default)]
pub struct DebugState {
    count: AtomicU64,
    messages: Mutex<Vec<String>>,
}

impl DebugState {
    pub fn count(&self) -> u64 {
        self.count.load(Ordering::SeqCst)
    }
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }
}

const KEPT_MESSAGES: usize = 64;

pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    ty: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let counted = ty
        .intersects(vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE)
        || severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR);
    if !counted || user.is_null() {
        return vk::FALSE;
    }
    let state = &*(user as *const DebugState);
    state.count.fetch_add(1, Ordering::SeqCst);
    let text = if data.is_null() || (*data).p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr((*data).p_message).to_string_lossy().into_owned()
    };
    if let Ok(mut m) = state.messages.lock() {
        if m.len() < KEPT_MESSAGES {
            m.push(format!("[{severity:?}] {text}"));
        }
    }
    vk::FALSE
}
