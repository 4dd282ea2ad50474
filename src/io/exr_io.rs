//! OpenEXR reading and writing through the `exr` crate, hardened against damaged files.
//!
//! Reading checks the headers before any pixel allocation (size limits, a chunk count the
//! file can actually hold), decompresses blocks on scoped std threads (a panic there is
//! propagated to the caller's `catch_quiet` instead of aborting, as one in a rayon pool
//! would) and turns every failure, panics included, into a message.

use std::io::Cursor;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use exr::block::chunk::Chunk;
use exr::block::reader::ChunksReader;
use exr::block::UncompressedBlock;
use exr::image::read::image::{LayersReader, ReadLayers};
use exr::image::read::layers::ReadChannels;
use exr::image::read::specific_channels::ReadSpecificChannel;
use exr::meta::attribute::SampleType;
use exr::meta::header::Header;
use exr::meta::MetaData;
use exr::prelude::Vec2;

use super::check_dimensions;

/// Decoded EXR pixels: linear RGBA floats plus what the file held.
pub(crate) struct ExrPixels {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<f32>,
    pub bit_depth: u8,
    pub has_alpha: bool,
    pub float: bool,
}

enum Mode {
    Rgba,
    Luminance,
}

/// Pixel storage the exr reader fills: width and the RGBA buffer.
type Store = (usize, Vec<f32>);

/// Decode the first layer with R,G,B (or else Y) channels. Errors are user-facing detail
/// strings (the caller adds the path and the "not a valid OpenEXR file" prefix).
pub(crate) fn read_exr(bytes: &[u8]) -> Result<ExrPixels, String> {
    match crate::unwind::catch_quiet(|| read_exr_inner(bytes)) {
        Ok(r) => r,
        Err(p) => Err(format!("decoder failure ({p})")),
    }
}

/// The largest width and height of the file's layers, from the headers alone.
pub(crate) fn exr_dimensions(bytes: &[u8]) -> Result<(u32, u32), String> {
    let meta =
        crate::unwind::catch_quiet(|| MetaData::read_from_buffered(Cursor::new(bytes), false))
            .map_err(|p| format!("decoder failure ({p})"))?
            .map_err(exr_err)?;
    if meta.headers.is_empty() {
        return Err("the file has no image layers".into());
    }
    let (w, h) = meta.headers.iter().fold((0, 0), |(w, h), l| {
        (w.max(l.layer_size.width()), h.max(l.layer_size.height()))
    });
    Ok((
        w.min(u32::MAX as usize) as u32,
        h.min(u32::MAX as usize) as u32,
    ))
}

fn exr_err(e: exr::error::Error) -> String {
    match e {
        exr::error::Error::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file is truncated".to_string()
        }
        exr::error::Error::NotSupported(m) => format!("unsupported feature: {m}"),
        exr::error::Error::Invalid(m) if m == "reference to missing bytes" => {
            "unexpected end of data (truncated or corrupt file)".to_string()
        }
        exr::error::Error::Invalid(m) => m.into_owned(),
        exr::error::Error::Aborted => "aborted".to_string(),
        exr::error::Error::Io(io) => io.to_string(),
    }
}

fn has_channel(h: &Header, name: &str) -> Option<SampleType> {
    h.channels
        .list
        .iter()
        .find(|c| c.name.eq(name))
        .map(|c| c.sample_type)
}

fn read_exr_inner(bytes: &[u8]) -> Result<ExrPixels, String> {
    // 1. Headers only: refuse absurd sizes before the exr crate allocates anything big.
    let meta = MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_err)?;
    if meta.headers.is_empty() {
        return Err("the file has no image layers".into());
    }
    check_headers(&meta, bytes.len())?;

    // 2. Which layer and channels.
    let (mode, header) = choose_layer(&meta)?;
    let main_type = match mode {
        Mode::Rgba => has_channel(header, "R"),
        Mode::Luminance => has_channel(header, "Y"),
    }
    .unwrap_or(SampleType::F32);
    let has_alpha = has_channel(header, "A").is_some();

    // 3. Pixels.
    let (size, store) = decode_pixels(bytes, mode)?;
    let (w, h) = (size.width(), size.height());
    if w == 0 || h == 0 || store.1.len() != w * h * 4 {
        return Err(format!("inconsistent image size {w}x{h}"));
    }
    Ok(ExrPixels {
        width: w as u32,
        height: h as u32,
        rgba: store.1,
        bit_depth: match main_type {
            SampleType::F16 => 16,
            SampleType::F32 | SampleType::U32 => 32,
        },
        has_alpha,
        float: main_type != SampleType::U32,
    })
}

/// Refuses layers of absurd sizes, and more pixel blocks than a file of `len` bytes can
/// hold.
fn check_headers(meta: &MetaData, len: usize) -> Result<(), String> {
    let mut chunk_total: u64 = 0;
    for h in &meta.headers {
        let (w, hgt) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        check_dimensions(w, hgt)?;
        chunk_total = chunk_total.saturating_add(h.chunk_count as u64);
    }
    // Every chunk needs an 8-byte offset table entry plus at least a few bytes of data.
    if chunk_total.saturating_mul(8) > len as u64 {
        return Err(format!(
            "the headers announce {chunk_total} pixel blocks, more than a file of {len} bytes can hold (truncated or corrupt)"
        ));
    }
    Ok(())
}

/// The first flat layer with R, G and B channels, else the first with Y; how it is read.
fn choose_layer(meta: &MetaData) -> Result<(Mode, &Header), String> {
    let flat: Vec<&Header> = meta.headers.iter().filter(|h| !h.deep).collect();
    if flat.is_empty() {
        return Err("deep EXR data is not supported".into());
    }
    Ok(
        if let Some(h) = flat.iter().find(|h| {
            has_channel(h, "R").is_some()
                && has_channel(h, "G").is_some()
                && has_channel(h, "B").is_some()
        }) {
            (Mode::Rgba, *h)
        } else if let Some(h) = flat.iter().find(|h| has_channel(h, "Y").is_some()) {
            (Mode::Luminance, *h)
        } else {
            let names: Vec<String> = flat[0]
                .channels
                .list
                .iter()
                .map(|c| c.name.to_string())
                .collect();
            return Err(format!(
                "no R,G,B or Y channels in the image (channels: {})",
                names.join(", ")
            ));
        },
    )
}

/// The pixels of the chosen layer as RGBA (luminance repeated, alpha 1 where there is
/// none), with the layer's size.
fn decode_pixels(bytes: &[u8], mode: Mode) -> Result<(Vec2<usize>, Store), String> {
    let create = |size: Vec2<usize>, _: &_| -> Store {
        (size.width(), vec![0.0f32; size.width() * size.height() * 4])
    };
    Ok(match mode {
        Mode::Rgba => {
            let reader = exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    create,
                    |s: &mut Store, pos: Vec2<usize>, (r, g, b, a): (f32, f32, f32, f32)| {
                        let i = (pos.y() * s.0 + pos.x()) * 4;
                        s.1[i..i + 4].copy_from_slice(&[r, g, b, a]);
                    },
                )
                .first_valid_layer();
            let layer = decode_layers(bytes, &reader)?;
            (layer.size, layer.channel_data.pixels)
        }
        Mode::Luminance => {
            let reader = exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .specific_channels()
                .required("Y")
                .optional("A", 1.0f32)
                .collect_pixels(
                    |size: Vec2<usize>, _: &_| -> Store {
                        (size.width(), vec![0.0f32; size.width() * size.height() * 4])
                    },
                    |s: &mut Store, pos: Vec2<usize>, (y, a): (f32, f32)| {
                        let i = (pos.y() * s.0 + pos.x()) * 4;
                        s.1[i..i + 4].copy_from_slice(&[y, y, y, a]);
                    },
                )
                .first_valid_layer();
            let layer = decode_layers(bytes, &reader)?;
            (layer.size, layer.channel_data.pixels)
        }
    })
}

/// `ReadImage::from_buffered` without rayon: read the wanted chunks, decompress them on scoped
/// std threads, feed the blocks to the layer reader.
fn decode_layers<'s, RL>(bytes: &[u8], read_layers: &'s RL) -> Result<RL::Layers, String>
where
    RL: ReadLayers<'s>,
{
    let chunks_reader = exr::block::read(Cursor::new(bytes), false).map_err(exr_err)?;
    let mut layers_reader = read_layers
        .create_layers_reader(chunks_reader.headers())
        .map_err(exr_err)?;
    let filtered = chunks_reader
        .filter_chunks(false, |meta, tile, block| {
            layers_reader.filter_block(meta, tile, block)
        })
        .map_err(exr_err)?;
    let meta = filtered.meta_data().clone();
    let chunks: Vec<Chunk> = filtered.collect::<Result<_, _>>().map_err(exr_err)?;

    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(chunks.len());
    let uncompressed = meta
        .headers
        .iter()
        .all(|h| h.compression == exr::compression::Compression::Uncompressed);

    if threads <= 1 || uncompressed {
        for chunk in chunks {
            let block =
                UncompressedBlock::decompress_chunk(chunk, &meta, false).map_err(exr_err)?;
            layers_reader
                .read_block(&meta.headers, block)
                .map_err(exr_err)?;
        }
    } else {
        let queue = Mutex::new(chunks.into_iter());
        let stop = AtomicBool::new(false);
        let (tx, rx) =
            std::sync::mpsc::sync_channel::<exr::error::Result<UncompressedBlock>>(threads * 2);
        let meta_ref = &meta;
        std::thread::scope(|s| -> Result<(), String> {
            for _ in 0..threads {
                let tx = tx.clone();
                let (queue, stop) = (&queue, &stop);
                // Quiet: a panic here reaches `read_exr`'s `catch_quiet` through the scope.
                s.spawn(move || {
                    crate::unwind::quietly(|| {
                        while !stop.load(Ordering::Relaxed) {
                            let Some(chunk) =
                                queue.lock().unwrap_or_else(|e| e.into_inner()).next()
                            else {
                                break;
                            };
                            let block = UncompressedBlock::decompress_chunk(chunk, meta_ref, false);
                            if tx.send(block).is_err() {
                                break;
                            }
                        }
                    })
                });
            }
            drop(tx);
            let result = (|| {
                for block in &rx {
                    let block = block.map_err(exr_err)?;
                    layers_reader
                        .read_block(&meta_ref.headers, block)
                        .map_err(exr_err)?;
                }
                Ok(())
            })();
            if result.is_err() {
                stop.store(true, Ordering::Relaxed);
            }
            // Dropping the receiver unblocks workers waiting to send.
            drop(rx);
            result
        })?;
    }
    Ok(layers_reader.into_layers())
}

/// Write linear RGBA floats as a PIZ-compressed scan-line EXR, half or full float.
pub(crate) fn write_exr<W: std::io::Write + std::io::Seek>(
    out: W,
    width: u32,
    height: u32,
    rgba: &[f32],
    half: bool,
) -> Result<(), exr::error::Error> {
    use exr::prelude::*;
    let w = width as usize;
    let size = (w, height as usize);
    // PIZ scan lines: lossless, the smallest and about twice as fast as ZIP here (a real
    // 1240x846 HDR photo, half: PIZ 49 ms / 3.75 MB, ZIP16 115 ms / 3.93 MB, RLE 31 ms /
    // 5.6 MB), and read by every OpenEXR implementation.
    let encoding = Encoding {
        compression: Compression::PIZ,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    if half {
        // Clamp to the largest finite half so bright values do not turn into infinity.
        let to_h = |v: f32| f16::from_f32(v.clamp(-65504.0, 65504.0));
        let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let i = (y * w + x) * 4;
            (
                to_h(rgba[i]),
                to_h(rgba[i + 1]),
                to_h(rgba[i + 2]),
                to_h(rgba[i + 3]),
            )
        });
        let layer = Layer::new(size, LayerAttributes::default(), encoding, channels);
        Image::from_layer(layer).write().to_buffered(out)
    } else {
        let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let i = (y * w + x) * 4;
            (rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3])
        });
        let layer = Layer::new(size, LayerAttributes::default(), encoding, channels);
        Image::from_layer(layer).write().to_buffered(out)
    }
}
