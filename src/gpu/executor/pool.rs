//! The texture pool: transient textures keyed by descriptor, reused across frames
//! and across the effects prepared on one [`Engine`](super::Engine).
//!
//! The plan's `Alloc { create: true }` takes a texture of the slot's descriptor
//! from the pool (creating one only when none is free) and `Free { release: true }`
//! gives it back; both are O(1). Every texture keeps the views the passes need (its
//! natural format, and the sRGB / raw alternative of 8-bit formats), made once.
//! A free texture unused for [`TexturePool::keep_frames`] frames is destroyed, so a
//! batch of images of changing sizes does not keep every size alive.

use super::wgpu_format;
use crate::gpu::transfer::texture_2d;
use crate::graph::plan::TextureDesc;
use crate::script::types::Format;
use std::collections::HashMap;

/// A texture with its views, made once.
pub(crate) struct PooledTexture {
    pub texture: wgpu::Texture,
    /// The view in the format of the plan's descriptor.
    pub natural: wgpu::TextureView,
    /// That format (`rgba8-srgb` textures of compute engines are made as
    /// `rgba8unorm` with an sRGB view: a storage texture cannot be sRGB).
    pub natural_format: wgpu::TextureFormat,
    /// The view in the other 8-bit format (`rgba8` seen as sRGB, `rgba8-srgb` seen
    /// raw), where the backend allows one.
    pub alternate: Option<(wgpu::TextureFormat, wgpu::TextureView)>,
    pub desc: TextureDesc,
    /// A mipmapped texture (`desc.mips > 1`): one view of each level in the
    /// natural format (the targets of the chain's passes), and level 0 in the
    /// alternate format. Empty for one level: the views above are the targets.
    pub levels: Vec<wgpu::TextureView>,
    pub alternate_level0: Option<wgpu::TextureView>,
    /// Unique on the engine (never reused, unlike pool indices): what bind groups
    /// are cached by.
    pub id: u64,
    /// Frame counter value of the last frame that used it.
    last_used: u64,
}

impl PooledTexture {
    /// A texture usable as render target, sampled input and copy source, and as
    /// a storage texture when `storage` (compute execution).
    pub fn create(
        device: &wgpu::Device,
        gl: bool,
        label: &str,
        desc: TextureDesc,
        id: u64,
        storage: bool,
    ) -> Self {
        let natural_format = wgpu_format(desc.format);
        // An sRGB texture cannot be bound for storage: under compute an sRGB
        // texture is made in its raw twin format, its natural view is sRGB, and
        // compute passes encode in the shader.
        let twin = storage && natural_format.is_srgb() && !gl;
        let format = if twin {
            natural_format.remove_srgb_suffix()
        } else {
            natural_format
        };
        let alternate = if gl {
            None
        } else {
            match desc.format {
                Format::Rgba8 => Some(wgpu::TextureFormat::Rgba8UnormSrgb),
                Format::Rgba8Srgb => Some(wgpu::TextureFormat::Rgba8Unorm),
                _ => None,
            }
        };
        let view_formats: Vec<wgpu::TextureFormat> = if twin {
            vec![natural_format]
        } else {
            alternate.into_iter().collect()
        };
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        if storage {
            usage |= wgpu::TextureUsages::STORAGE_BINDING;
        }
        let size = (desc.width, desc.height);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            mip_level_count: desc.mips,
            ..texture_2d(label, size, format, usage, &view_formats)
        });
        // A view inherits the texture's usages; an sRGB view cannot be a storage one.
        let view_usage = |f: wgpu::TextureFormat| {
            f.is_srgb()
                .then_some(usage - wgpu::TextureUsages::STORAGE_BINDING)
        };
        let natural = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(&format!("{label} view")),
            format: Some(natural_format),
            usage: view_usage(natural_format),
            ..Default::default()
        });
        let alternate = alternate.map(|f| {
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{label} view {f:?}")),
                format: Some(f),
                usage: view_usage(f),
                ..Default::default()
            });
            (f, view)
        });
        let level_view = |f: wgpu::TextureFormat, level: u32| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{label} level {level} view {f:?}")),
                format: Some(f),
                usage: view_usage(f),
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let (levels, alternate_level0) = if desc.mips > 1 {
            (
                (0..desc.mips)
                    .map(|l| level_view(natural_format, l))
                    .collect(),
                alternate.as_ref().map(|(f, _)| level_view(*f, 0)),
            )
        } else {
            (Vec::new(), None)
        };
        PooledTexture {
            texture,
            natural,
            natural_format,
            alternate,
            desc,
            levels,
            alternate_level0,
            id,
            last_used: 0,
        }
    }

    /// The view a pass writing this texture renders to (or stores to) in
    /// `format`: as [`PooledTexture::view`], but only level 0 of a mipmapped
    /// texture (a target has one level).
    pub fn target_view(&self, format: Option<wgpu::TextureFormat>) -> Option<&wgpu::TextureView> {
        if self.levels.is_empty() {
            return self.view(format);
        }
        match format {
            None => Some(&self.levels[0]),
            Some(f) if f == self.natural_format => Some(&self.levels[0]),
            Some(f) => self
                .alternate
                .as_ref()
                .filter(|(af, _)| *af == f)
                .and(self.alternate_level0.as_ref()),
        }
    }

    /// The view in `format` (`None`: the texture's own); `None` when the texture
    /// has no such view.
    pub fn view(&self, format: Option<wgpu::TextureFormat>) -> Option<&wgpu::TextureView> {
        match format {
            None => Some(&self.natural),
            Some(f) if f == self.natural_format => Some(&self.natural),
            Some(f) => self
                .alternate
                .as_ref()
                .filter(|(af, _)| *af == f)
                .map(|(_, v)| v),
        }
    }
}

/// The source of [`PooledTexture::id`]s.
#[derive(Debug, Default)]
pub(crate) struct Ids(u64);

impl Ids {
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u64 {
        self.0 += 1;
        self.0
    }
}

/// Counters of the pool (see [`super::EngineStats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PoolStats {
    /// Textures created since the engine was made.
    pub created: u64,
    /// Textures destroyed after staying unused for `keep_frames` frames.
    pub destroyed: u64,
    /// Textures held now (in use or free).
    pub held: usize,
    /// Bytes of the textures held now.
    pub held_bytes: u64,
}

/// Transient textures by descriptor.
pub(crate) struct TexturePool {
    textures: Vec<Option<PooledTexture>>,
    free: HashMap<TextureDesc, Vec<usize>>,
    /// Slots of `textures` emptied by trimming, reused by the next creation.
    vacant: Vec<usize>,
    /// Free textures unused for more frames than this are destroyed.
    pub keep_frames: u64,
    /// Formats whose textures are made with `STORAGE_BINDING` (compute execution).
    storage_formats: Vec<Format>,
    pub stats: PoolStats,
}

impl TexturePool {
    pub fn new() -> Self {
        TexturePool {
            textures: Vec::new(),
            free: HashMap::new(),
            vacant: Vec::new(),
            keep_frames: 8,
            storage_formats: Vec::new(),
            stats: PoolStats::default(),
        }
    }

    /// Textures of `formats` made from now on can be storage textures.
    pub fn set_storage_formats(&mut self, formats: Vec<Format>) {
        self.storage_formats = formats;
    }

    /// Textures of `format` made from now on can be storage textures too (a
    /// compute-native pass writes that format).
    pub fn add_storage_format(&mut self, format: Format) {
        if !self.storage_formats.contains(&format) {
            self.storage_formats.push(format);
        }
    }

    /// Whether textures of `format` made now can be storage textures.
    pub fn stores(&self, format: Format) -> bool {
        self.storage_formats.contains(&format)
    }

    /// A texture of `desc`: the most recently freed one, or a new one.
    pub fn acquire(
        &mut self,
        device: &wgpu::Device,
        gl: bool,
        desc: TextureDesc,
        ids: &mut Ids,
    ) -> usize {
        let storage = self.stores(desc.format);
        let textures = &self.textures;
        // A free texture made before its format needed storage is left to trim.
        let usable = |i: &usize| {
            !storage
                || textures[*i].as_ref().is_some_and(|t| {
                    t.texture
                        .usage()
                        .contains(wgpu::TextureUsages::STORAGE_BINDING)
                })
        };
        if let Some(list) = self.free.get_mut(&desc) {
            if let Some(at) = list.iter().rposition(usable) {
                return list.remove(at);
            }
        }
        let label = format!(
            "fxgraph pooled {}x{} {} #{}",
            desc.width, desc.height, desc.format, self.stats.created
        );
        let t = PooledTexture::create(device, gl, &label, desc, ids.next(), storage);
        self.stats.created += 1;
        self.stats.held += 1;
        self.stats.held_bytes += desc.bytes();
        match self.vacant.pop() {
            Some(i) => {
                self.textures[i] = Some(t);
                i
            }
            None => {
                self.textures.push(Some(t));
                self.textures.len() - 1
            }
        }
    }

    /// Give texture `i` back; `frame` is the engine's frame counter.
    pub fn release(&mut self, i: usize, frame: u64) {
        let t = self.textures[i].as_mut().expect("a held texture");
        t.last_used = frame;
        self.free.entry(t.desc).or_default().push(i);
    }

    pub fn get(&self, i: usize) -> &PooledTexture {
        self.textures[i].as_ref().expect("a held texture")
    }

    /// Destroy free textures last used more than `keep_frames` frames before `frame`.
    pub fn trim(&mut self, frame: u64) {
        let keep = self.keep_frames;
        let textures = &mut self.textures;
        let stats = &mut self.stats;
        let vacant = &mut self.vacant;
        for list in self.free.values_mut() {
            list.retain(|&i| {
                let t = textures[i].as_ref().expect("a held texture");
                if frame.saturating_sub(t.last_used) <= keep {
                    return true;
                }
                let t = textures[i].take().expect("a held texture");
                stats.destroyed += 1;
                stats.held -= 1;
                stats.held_bytes -= t.desc.bytes();
                t.texture.destroy();
                vacant.push(i);
                false
            });
        }
        self.free.retain(|_, l| !l.is_empty());
    }
}
