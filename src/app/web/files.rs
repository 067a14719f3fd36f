//! The page's files. The browser's file picker, a file dropped on the
//! page and `?open=URL` hand octovox bytes: they go into the page's files
//! (`octovox::io::page_files`) under their names, and the command the
//! desktop's dialog would give for that name opens them, through the same
//! loaders. A name to write (Save As, Export) is asked for by the
//! browser's prompt; what octovox writes is handed over as a download.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use wasm_bindgen::JsCast as _;
use wasm_bindgen::closure::Closure;
use wasm_bindgen_futures::JsFuture;

use octovox::io::page_files;

use super::super::AppCommand;
use super::super::dialog_kind::DialogKind;

/// A file the page was given, and what to do with it.
struct Given {
    name: String,
    bytes: Vec<u8>,
    kind: DialogKind,
}

/// Files given to the page that the next frame takes.
#[derive(Clone, Default)]
pub struct Inbox {
    given: Rc<RefCell<Vec<Given>>>,
    /// Why a file could not be had (a fetch that failed).
    failed: Rc<RefCell<Vec<String>>>,
}

impl Inbox {
    /// Asks the user for a file of `kind` to read (the browser's picker),
    /// or for a name to write one as (the browser's prompt, `start` offered).
    pub fn ask(&self, ctx: &egui::Context, kind: DialogKind, start: &str) -> Option<AppCommand> {
        if kind.opens() {
            if let Err(err) = self.pick(ctx, kind) {
                self.failed.borrow_mut().push(format!("cannot show the file picker: {err}"));
            }
            return None;
        }
        let offered = Path::new(start).file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let window = web_sys::window()?;
        let name = window.prompt_with_message_and_default(kind.title(), &offered).ok().flatten()?;
        let name = name.trim();
        (!name.is_empty()).then(|| kind.command(PathBuf::from(name)))
    }

    /// Opens the browser's file picker; the chosen file arrives later.
    fn pick(&self, ctx: &egui::Context, kind: DialogKind) -> Result<(), String> {
        let document = web_sys::window().and_then(|w| w.document()).ok_or("no document")?;
        let input: web_sys::HtmlInputElement = document
            .create_element("input")
            .map_err(|e| super::js_text(&e))?
            .dyn_into()
            .map_err(|_| "not an input element")?;
        input.set_type("file");
        let accept: Vec<String> = kind.extensions().iter().map(|e| format!(".{e}")).collect();
        input.set_accept(&accept.join(","));
        let (inbox, ctx, chosen) = (self.clone(), ctx.clone(), input.clone());
        let on_change = Closure::once(move || {
            if let Some(file) = chosen.files().and_then(|files| files.get(0)) {
                inbox.read(file, kind, ctx);
            }
        });
        input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
        // The closure lives as long as the input (the page never frees it).
        on_change.forget();
        input.click();
        Ok(())
    }

    /// Reads a chosen file's bytes, then hands it to the next frame.
    fn read(&self, file: web_sys::File, kind: DialogKind, ctx: egui::Context) {
        let inbox = self.clone();
        wasm_bindgen_futures::spawn_local(async move {
            match JsFuture::from(file.array_buffer()).await {
                Ok(buffer) => {
                    let bytes = js_sys::Uint8Array::new(&buffer).to_vec();
                    inbox.given.borrow_mut().push(Given { name: file.name(), bytes, kind });
                }
                Err(err) => {
                    inbox.failed.borrow_mut().push(format!("cannot read {}: {}", file.name(), super::js_text(&err)))
                }
            }
            ctx.request_repaint();
        });
    }

    /// Fetches `url` and opens it (`?open=URL`, a model shared as a link).
    pub fn fetch(&self, url: String, ctx: egui::Context) {
        let inbox = self.clone();
        wasm_bindgen_futures::spawn_local(async move {
            match fetch_bytes(&url).await {
                Ok(bytes) => {
                    let name = url.split(['?', '#']).next().and_then(|u| u.rsplit('/').next()).unwrap_or("shared.vox");
                    inbox.given.borrow_mut().push(Given { name: name.to_string(), bytes, kind: DialogKind::Open });
                }
                Err(err) => inbox.failed.borrow_mut().push(format!("cannot open {url}: {err}")),
            }
            ctx.request_repaint();
        });
    }

    /// A file dropped on the page, opened as File ▸ Open opens it (a replay
    /// script is played) once the browser has read it.
    pub fn dropped(&self, file: egui::DroppedFileHandle, ctx: egui::Context) {
        let inbox = self.clone();
        wasm_bindgen_futures::spawn_local(async move {
            let name = file.path().file_name().map_or_else(|| "dropped".into(), |n| n.to_string_lossy().into_owned());
            match file.bytes_async().await {
                Ok(bytes) => {
                    let script = name.to_ascii_lowercase().ends_with(".ovr");
                    let kind = if script { DialogKind::PlayScript } else { DialogKind::Open };
                    inbox.given.borrow_mut().push(Given { name, bytes, kind });
                }
                Err(err) => inbox.failed.borrow_mut().push(format!("cannot read {name}: {err}")),
            }
            ctx.request_repaint();
        });
    }

    /// The commands for the files given since the last call (each now one of
    /// the page's files), and why any could not be had.
    pub fn take(&self) -> (Vec<AppCommand>, Vec<String>) {
        let commands = self
            .given
            .borrow_mut()
            .drain(..)
            .map(|given| {
                let path = PathBuf::from(given.name);
                page_files::provide(&path, given.bytes);
                given.kind.command(path)
            })
            .collect();
        (commands, std::mem::take(&mut *self.failed.borrow_mut()))
    }
}

async fn fetch_bytes(url: &str) -> Result<Vec<u8>, String> {
    let window = web_sys::window().ok_or("no window")?;
    let response: web_sys::Response =
        JsFuture::from(window.fetch_with_str(url)).await.map_err(|e| super::js_text(&e))?.unchecked_into();
    if !response.ok() {
        return Err(format!("HTTP {}", response.status()));
    }
    let buffer = JsFuture::from(response.array_buffer().map_err(|e| super::js_text(&e))?)
        .await
        .map_err(|e| super::js_text(&e))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}

/// Hands every file octovox wrote since the last call to the user as a
/// download named as the file. Returns the names.
pub fn download_written() -> Vec<String> {
    page_files::take_written()
        .into_iter()
        .filter_map(|(path, bytes)| {
            let name = path.file_name()?.to_string_lossy().into_owned();
            match download(&name, &bytes) {
                Ok(()) => Some(name),
                Err(err) => {
                    log::error!("cannot download {name}: {err}");
                    None
                }
            }
        })
        .collect()
}

fn download(name: &str, bytes: &[u8]) -> Result<(), String> {
    let document = web_sys::window().and_then(|w| w.document()).ok_or("no document")?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let blob = web_sys::Blob::new_with_u8_array_sequence(&parts).map_err(|e| super::js_text(&e))?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(|e| super::js_text(&e))?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(|e| super::js_text(&e))?
        .dyn_into()
        .map_err(|_| "not an anchor element")?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    // The download reads the URL after this returns: let it go a minute later.
    let revoke = Closure::once_into_js(move || {
        let _ = web_sys::Url::revoke_object_url(&url);
    });
    let window = web_sys::window().ok_or("no window")?;
    window
        .set_timeout_with_callback_and_timeout_and_arguments_0(revoke.unchecked_ref(), 60_000)
        .map_err(|e| super::js_text(&e))?;
    Ok(())
}

/// Prefix of the browser-storage keys of the page's kept files.
const STORED: &str = "octovox-file:";

/// The kept files (crash journals and their snapshots, the recent files
/// and their list) a page before this one left in the browser's storage,
/// back among the page's files: the session offers to recover the
/// journals as the desktop's does, and File ▸ Open recent lists the files.
pub fn restore_kept() {
    let Some(storage) = local_storage() else { return };
    let count = storage.length().unwrap_or(0);
    let keys: Vec<String> = (0..count).filter_map(|i| storage.key(i).ok().flatten()).collect();
    for key in keys {
        let Some(path) = key.strip_prefix(STORED) else { continue };
        if let Ok(Some(text)) = storage.get_item(&key) {
            // One char per byte (see `store_kept`).
            let bytes: Option<Vec<u8>> = text.chars().map(|c| u8::try_from(u32::from(c)).ok()).collect();
            match bytes {
                Some(bytes) => {
                    page_files::provide(Path::new(path), bytes);
                    page_files::keep(Path::new(path), true);
                }
                None => log::warn!("the stored {path} is not octovox's: left alone"),
            }
        }
    }
}

/// The documents whose journals the browser kept: their unsaved edits
/// are offered back when they are opened again.
pub fn kept_documents() -> Vec<PathBuf> {
    let mut documents: Vec<PathBuf> =
        page_files::list(Path::new("")).iter().filter_map(|journal| octovox::journal::document_of(journal)).collect();
    documents.sort();
    documents
}

/// Stores the kept files changed this frame in the browser's storage (and
/// forgets removed ones), so that a closed or crashed tab leaves them.
/// Bytes are stored one char each: storage holds text.
pub fn store_kept() {
    let changed = page_files::take_changed();
    if changed.is_empty() {
        return;
    }
    let Some(storage) = local_storage() else { return };
    for (path, bytes) in changed {
        let key = format!("{STORED}{}", path.display());
        let stored = match bytes {
            Some(bytes) => storage.set_item(&key, &bytes.iter().map(|&b| char::from(b)).collect::<String>()),
            None => storage.remove_item(&key),
        };
        if let Err(err) = stored {
            log::error!("cannot keep {} in the browser's storage: {}", path.display(), super::js_text(&err));
        }
    }
}

fn local_storage() -> Option<web_sys::Storage> {
    web_sys::window()?.local_storage().ok().flatten()
}
