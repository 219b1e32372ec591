//! The validation layer's messages: the log a debug messenger appends to, and
//! the messenger itself. Any message is an error: callers drain the log with
//! `Context::check_validation`, and teardown reports what is left in it.

use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex};

use anyhow::{bail, Result};
use ash::{ext, vk};

use super::error::VkResult;

/// Validation messages collected by the debug messenger.
pub type MessageLog = Arc<Mutex<Vec<String>>>;

/// The log the messenger fills. The messenger's callback holds a pointer to
/// it, so the log is boxed (its address stays put when the owner moves) and
/// must outlive every messenger made from [`ValidationLog::messenger_info`].
pub struct ValidationLog {
    log: Box<MessageLog>,
}

impl Default for ValidationLog {
    fn default() -> Self {
        ValidationLog {
            log: Box::new(Arc::new(Mutex::new(Vec::new()))),
        }
    }
}

impl ValidationLog {
    /// A messenger's create-info that appends warnings and errors, validation
    /// and performance ones, to this log. Chained into the instance's
    /// create-info it catches the messages of the instance's own creation.
    pub fn messenger_info(&self) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
        vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                    | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(&*self.log as *const MessageLog as *mut c_void)
    }

    /// Returns every message received since the last call as an error.
    pub fn check(&self, when: &str) -> Result<()> {
        let mut v = self.log.lock().expect("validation log poisoned");
        if v.is_empty() {
            return Ok(());
        }
        let all = std::mem::take(&mut *v);
        bail!(
            "{} validation message(s) {when}:\n{}",
            all.len(),
            all.join("\n")
        )
    }

    /// Every message received since the last call (none from a poisoned
    /// log: teardown reports what it can).
    pub fn take(&self) -> Vec<String> {
        self.log
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    if data.is_null() || user.is_null() {
        return vk::FALSE;
    }
    let data = &*data;
    let msg = if data.p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr(data.p_message)
            .to_string_lossy()
            .into_owned()
    };
    let log = &*(user as *const MessageLog);
    if let Ok(mut v) = log.lock() {
        v.push(format!("[{severity:?} {kind:?}] {msg}"));
    }
    vk::FALSE
}

/// A debug messenger on an instance, appending to a [`ValidationLog`].
pub struct Messenger {
    loader: ext::debug_utils::Instance,
    raw: vk::DebugUtilsMessengerEXT,
}

impl Messenger {
    /// A messenger into `log`, which must outlive it.
    pub fn new(
        entry: &ash::Entry,
        instance: &ash::Instance,
        log: &ValidationLog,
    ) -> VkResult<Self> {
        let loader = ext::debug_utils::Instance::new(entry, instance);
        let raw = unsafe { loader.create_debug_utils_messenger(&log.messenger_info(), None) }?;
        Ok(Messenger { loader, raw })
    }

    /// Destroys the messenger (before its instance).
    ///
    /// # Safety
    /// Once (the instance that owns it calls this from its own destroy).
    pub unsafe fn destroy(&self) {
        self.loader.destroy_debug_utils_messenger(self.raw, None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The callback appends to the log its create-info points at, and a check
    // drains it: one error naming every message, then nothing.
    #[test]
    fn the_callback_fills_the_log_a_check_drains() {
        let log = ValidationLog::default();
        assert!(log.check("before").is_ok());
        let info = log.messenger_info();
        let text = c"VUID-test: something is off";
        let data = vk::DebugUtilsMessengerCallbackDataEXT::default().message(text);
        let callback = info.pfn_user_callback.unwrap();
        let severity = vk::DebugUtilsMessageSeverityFlagsEXT::ERROR;
        let kind = vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION;
        for _ in 0..2 {
            let r = unsafe { callback(severity, kind, &data, info.p_user_data) };
            assert_eq!(r, vk::FALSE);
        }
        let e = log.check("in a test").unwrap_err().to_string();
        assert!(e.starts_with("2 validation message(s) in a test:"), "{e}");
        assert!(
            e.contains("[ERROR VALIDATION] VUID-test: something is off"),
            "{e}"
        );
        assert!(log.check("after").is_ok());
    }
}
