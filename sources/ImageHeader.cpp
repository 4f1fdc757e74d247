// SPDX-License-Identifier: LGPL-2.1-or-later
// Image header reader: signatures, sizes and cheap completeness checks for PNG, JPEG, TIFF, BMP,
// WebP and OpenEXR, with every read bounds-checked.
#include "sources/ImageHeader.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace defocus {
namespace {

using Bytes = std::span<const unsigned char>;

bool startsWith(Bytes bytes, std::initializer_list<unsigned char> signature)
{
    return bytes.size() >= signature.size() && std::equal(signature.begin(), signature.end(), bytes.begin());
}

// Unsigned integers of `n` bytes at `at`, or nullopt past the end.
std::optional<std::uint64_t> readBe(Bytes bytes, std::size_t at, std::size_t n)
{
    if (at > bytes.size() || bytes.size() - at < n)
        return std::nullopt;
    std::uint64_t value = 0;
    for (std::size_t i = 0; i < n; ++i)
        value = value << 8 | bytes[at + i];
    return value;
}

std::optional<std::uint64_t> readLe(Bytes bytes, std::size_t at, std::size_t n)
{
    if (at > bytes.size() || bytes.size() - at < n)
        return std::nullopt;
    std::uint64_t value = 0;
    for (std::size_t i = n; i-- > 0;)
        value = value << 8 | bytes[at + i];
    return value;
}

std::int64_t asSigned32(std::uint64_t value)
{
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(value));
}

ImageHeader failed(ImageFormat format, std::string problem)
{
    ImageHeader header;
    header.format = format;
    header.problem = std::move(problem);
    return header;
}

ImageHeader sized(ImageFormat format, std::uint64_t width, std::uint64_t height)
{
    if (width == 0 || height == 0)
        return failed(format, fmt::format("the {} header gives a size of {}x{}", formatName(format), width, height));
    ImageHeader header;
    header.format = format;
    header.width = width;
    header.height = height;
    return header;
}

std::string printable(Bytes type)
{
    std::string out;
    for (const unsigned char c : type)
        out += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
    return out;
}
std::string printable(std::string_view text)
{
    return printable(Bytes(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

// PNG (ISO/IEC 15948): signature, then chunks of length (4, big-endian), type (4), data, CRC (4);
// IHDR first (width, height), IEND last. libpng checks the CRCs.
ImageHeader readPng(Bytes bytes)
{
    constexpr std::size_t signature = 8;
    const auto ihdrLength = readBe(bytes, signature, 4);
    if (!ihdrLength || !startsWith(bytes.subspan(std::min(bytes.size(), signature + 4)), {'I', 'H', 'D', 'R'}) ||
        *ihdrLength != 13)
        return failed(ImageFormat::Png, "corrupt PNG: it does not start with an IHDR chunk");
    const auto width = readBe(bytes, 16, 4);
    const auto height = readBe(bytes, 20, 4);
    if (!width || !height)
        return failed(ImageFormat::Png, "truncated PNG: it ends inside the IHDR chunk");
    ImageHeader header = sized(ImageFormat::Png, *width, *height);
    if (!header.problem.empty())
        return header;
    std::size_t at = signature;
    while (true) {
        const auto length = readBe(bytes, at, 4);
        if (!length)
            return failed(ImageFormat::Png, fmt::format("truncated PNG: it ends at byte {} with no IEND chunk", bytes.size()));
        const Bytes type = bytes.subspan(at + 4, std::min<std::size_t>(4, bytes.size() - at - 4));
        if (*length > 0x7fffffffu)
            return failed(ImageFormat::Png, fmt::format("corrupt PNG: chunk '{}' at byte {} claims {} bytes",
                                                        printable(type), at, *length));
        const std::uint64_t end = at + 12 + *length;
        if (end > bytes.size())
            return failed(ImageFormat::Png, fmt::format("truncated PNG: it ends at byte {}, inside chunk '{}' that "
                                                        "starts at byte {}",
                                                        bytes.size(), printable(type), at));
        if (startsWith(type, {'I', 'E', 'N', 'D'}))
            return header;
        at = static_cast<std::size_t>(end);
    }
}

bool isJpegFrameMarker(unsigned marker)
{
    // SOF0-SOF15 except DHT (C4), JPG (C8) and DAC (CC).
    return marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
}

// JPEG (ITU T.81): SOI, marker segments (FF xx, then a big-endian length that counts itself),
// entropy-coded data after each SOS in which FF is followed by 00 (a stuffed FF) or a restart
// marker D0-D7, and EOI. libjpeg decodes a file cut short by padding it grey with only a
// warning, so completeness is checked here: the walk must reach EOI.
ImageHeader readJpeg(Bytes bytes)
{
    std::optional<ImageHeader> frame;
    std::size_t at = 2;
    while (true) {
        // Skip anything up to the next marker (libjpeg does the same, with a warning).
        while (at < bytes.size() && bytes[at] != 0xff)
            ++at;
        while (at < bytes.size() && bytes[at] == 0xff)
            ++at;
        if (at >= bytes.size())
            return failed(ImageFormat::Jpeg, fmt::format("truncated JPEG: it ends at byte {} with no end-of-image "
                                                         "marker",
                                                         bytes.size()));
        const unsigned marker = bytes[at++];
        if (marker == 0xd9) {
            if (!frame)
                return failed(ImageFormat::Jpeg, "corrupt JPEG: it has no frame header (SOF)");
            return *frame;
        }
        if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7))
            continue; // no length
        const auto length = readBe(bytes, at, 2);
        if (!length || *length < 2 || at + *length > bytes.size())
            return failed(ImageFormat::Jpeg, fmt::format("truncated JPEG: it ends at byte {}, inside the segment "
                                                         "of marker FF{:02X} at byte {}",
                                                         bytes.size(), marker, at - 2));
        if (isJpegFrameMarker(marker) && !frame) {
            const auto height = readBe(bytes, at + 3, 2);
            const auto width = readBe(bytes, at + 5, 2);
            if (!height || !width || *length < 8)
                return failed(ImageFormat::Jpeg, "corrupt JPEG: its frame header is too short");
            frame = sized(ImageFormat::Jpeg, *width, *height);
            if (!frame->problem.empty())
                return *frame;
        }
        at += static_cast<std::size_t>(*length);
        if (marker == 0xda) {
            if (!frame)
                return failed(ImageFormat::Jpeg, "corrupt JPEG: its image data comes before the frame header (SOF)");
            // Entropy-coded data: runs to the first FF that starts a real marker.
            while (at + 1 < bytes.size() &&
                   !(bytes[at] == 0xff && bytes[at + 1] != 0x00 && !(bytes[at + 1] >= 0xd0 && bytes[at + 1] <= 0xd7)))
                ++at;
            if (at + 1 >= bytes.size())
                return failed(ImageFormat::Jpeg, fmt::format("truncated JPEG: it ends at byte {}, inside the "
                                                             "compressed image data",
                                                             bytes.size()));
        }
    }
}

// TIFF 6.0 and BigTIFF: byte order, then the first IFD's ImageWidth (256), ImageLength (257),
// TileWidth (322) and TileLength (323). Only the first image is read, as OpenCV does.
ImageHeader readTiff(Bytes bytes)
{
    const bool little = bytes[0] == 'I';
    const auto read = [&](std::size_t at, std::size_t n) { return little ? readLe(bytes, at, n) : readBe(bytes, at, n); };
    const auto version = read(2, 2);
    const bool big = version == 43u;
    const auto ifd = big ? read(8, 8) : read(4, 4);
    if (!ifd)
        return failed(ImageFormat::Tiff, "truncated TIFF: it ends inside the file header");
    if (*ifd >= bytes.size())
        return failed(ImageFormat::Tiff, fmt::format("truncated TIFF: its first directory is at byte {}, past the "
                                                     "end at byte {}",
                                                     *ifd, bytes.size()));
    const std::size_t countSize = big ? 8 : 2;
    const std::size_t entrySize = big ? 20 : 12;
    const std::size_t valueSize = big ? 8 : 4;
    const auto count = read(static_cast<std::size_t>(*ifd), countSize);
    if (!count || *count > (bytes.size() - *ifd - countSize) / entrySize)
        return failed(ImageFormat::Tiff, "truncated TIFF: it ends inside its first directory");
    // The size tags must be single SHORT, LONG or LONG8 values, each given once: libtiff
    // converts other types and keeps the first of duplicates, and any disagreement with it
    // would let a file slip past the size limit.
    std::array<std::optional<std::uint64_t>, 4> sizes; // width, height, tile width, tile height
    constexpr std::array<std::uint64_t, 4> sizeTags = {256, 257, 322, 323};
    for (std::uint64_t i = 0; i < *count; ++i) {
        const auto entry = static_cast<std::size_t>(*ifd + countSize + i * entrySize);
        const std::uint64_t tag = *read(entry, 2);
        const auto which = std::find(sizeTags.begin(), sizeTags.end(), tag);
        if (which == sizeTags.end())
            continue;
        const std::uint64_t type = *read(entry + 2, 2);
        const std::uint64_t values = *read(entry + 4, big ? 8 : 4);
        const std::size_t valueAt = entry + 4 + valueSize;
        std::optional<std::uint64_t>& size = sizes[static_cast<std::size_t>(which - sizeTags.begin())];
        if (size || values != 1 || !(type == 3 || type == 4 || (type == 16 && big)))
            return failed(ImageFormat::Tiff, fmt::format("corrupt TIFF: size tag {} is repeated or not one "
                                                         "integer",
                                                         tag));
        // Values sit left-aligned in the value field.
        size = *read(valueAt, type == 3 ? 2 : type == 4 ? 4 : 8);
    }
    const std::uint64_t width = sizes[0].value_or(0), height = sizes[1].value_or(0);
    const std::uint64_t tileWidth = sizes[2].value_or(0), tileHeight = sizes[3].value_or(0);
    ImageHeader header = sized(ImageFormat::Tiff, width, height);
    if (tileWidth > 0 || tileHeight > 0) {
        if (tileWidth == 0 || tileHeight == 0 || tileWidth > 0xffffffffu || tileHeight > 0xffffffffu)
            return failed(ImageFormat::Tiff, fmt::format("corrupt TIFF: tiles of {}x{}", tileWidth, tileHeight));
        header.tilePixels = tileWidth * tileHeight;
    }
    return header;
}

// BMP: BITMAPFILEHEADER (14 bytes), then an info header whose size tells the version: 12 for
// OS/2 (16-bit sizes), 40 and up for Windows (signed 32-bit; a negative height is top-down).
ImageHeader readBmp(Bytes bytes)
{
    const auto infoSize = readLe(bytes, 14, 4);
    if (!infoSize)
        return failed(ImageFormat::Bmp, "truncated BMP: it ends inside the file header");
    if (*infoSize == 12) {
        const auto width = readLe(bytes, 18, 2);
        const auto height = readLe(bytes, 20, 2);
        if (!width || !height)
            return failed(ImageFormat::Bmp, "truncated BMP: it ends inside the info header");
        return sized(ImageFormat::Bmp, *width, *height);
    }
    const auto width = readLe(bytes, 18, 4);
    const auto height = readLe(bytes, 22, 4);
    if (!width || !height)
        return failed(ImageFormat::Bmp, "truncated BMP: it ends inside the info header");
    const std::int64_t w = asSigned32(*width);
    const std::int64_t h = asSigned32(*height);
    if (w <= 0)
        return failed(ImageFormat::Bmp, fmt::format("corrupt BMP: width {}", w));
    return sized(ImageFormat::Bmp, static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h < 0 ? -h : h));
}

// WebP: RIFF container (its size at byte 4 counts from byte 8), then one of three first chunks:
// "VP8 " (lossy: 14-bit sizes after a start code), "VP8L" (lossless: 14-bit sizes minus one,
// packed), "VP8X" (extended: 24-bit canvas sizes minus one).
ImageHeader readWebP(Bytes bytes)
{
    const auto riffSize = readLe(bytes, 4, 4);
    if (!riffSize || bytes.size() < 30)
        return failed(ImageFormat::WebP, "truncated WebP: it ends inside the header");
    if (*riffSize + 8 > bytes.size())
        return failed(ImageFormat::WebP, fmt::format("truncated WebP: its header says {} bytes, the file has {}",
                                                     *riffSize + 8, bytes.size()));
    const Bytes chunk = bytes.subspan(12, 4);
    if (startsWith(chunk, {'V', 'P', '8', ' '})) {
        if (!startsWith(bytes.subspan(23), {0x9d, 0x01, 0x2a}))
            return failed(ImageFormat::WebP, "corrupt WebP: no VP8 start code");
        return sized(ImageFormat::WebP, *readLe(bytes, 26, 2) & 0x3fff, *readLe(bytes, 28, 2) & 0x3fff);
    }
    if (startsWith(chunk, {'V', 'P', '8', 'L'})) {
        if (bytes[20] != 0x2f)
            return failed(ImageFormat::WebP, "corrupt WebP: no VP8L signature");
        const std::uint64_t bits = *readLe(bytes, 21, 4);
        return sized(ImageFormat::WebP, (bits & 0x3fff) + 1, (bits >> 14 & 0x3fff) + 1);
    }
    if (startsWith(chunk, {'V', 'P', '8', 'X'}))
        return sized(ImageFormat::WebP, *readLe(bytes, 24, 3) + 1, *readLe(bytes, 27, 3) + 1);
    return failed(ImageFormat::WebP, fmt::format("unsupported WebP: first chunk '{}'", printable(chunk)));
}

// How many bytes OpenEXR reads for a value of `type` at `at`, where it reads a type it knows by
// its content rather than by the size the header gives: a fixed size, a channel list up to its
// empty name, a preview by its width and height. nullopt: a type read by its size (strings,
// vectors, every type OpenEXR does not know). A channel list that runs off the file counts one
// byte more than there is.
std::optional<std::uint64_t> exrValueBytes(std::string_view type, Bytes bytes, std::size_t at)
{
    static constexpr std::array<std::pair<std::string_view, std::uint64_t>, 24> fixed = {{
        {"box2i", 16}, {"box2f", 16}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24},
        {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128}, {"int", 4}, {"float", 4}, {"double", 8},
        {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1}, {"rational", 8},
        {"timecode", 8}, {"keycode", 28}, {"chromaticities", 32}, {"tiledesc", 9},
    }};
    for (const auto& [name, size] : fixed)
        if (type == name)
            return size;
    if (type == "chlist") {
        // Channels: a name (at most 255 bytes) NUL, 16 bytes of pixel type and sampling; an empty
        // name ends the list.
        std::size_t end = at;
        while (true) {
            const std::size_t start = end;
            while (end < bytes.size() && bytes[end] != 0 && end - start <= 255)
                ++end;
            if (end >= bytes.size() || end - start > 255)
                return bytes.size() - at + 1;
            if (end++ == start)
                return end - at;
            end += 16;
        }
    }
    if (type == "preview") {
        const auto width = readLe(bytes, at, 4), height = readLe(bytes, at + 4, 4);
        if (!width || !height)
            return bytes.size() - at + 1;
        return 8 + 4 * *width * *height;
    }
    return std::nullopt;
}

// OpenEXR: magic, a version word with flags, then attributes (name NUL, type NUL, 32-bit size,
// value) up to an empty name. dataWindow (box2i: xMin, yMin, xMax, yMax) gives the size. A
// single-part scan-line file follows with one 64-bit offset per chunk of scan lines, each chunk
// starting with its y (4 bytes) and data size (4 bytes): all must lie inside the file.
ImageHeader readExr(Bytes bytes)
{
    constexpr std::uint64_t tiledFlag = 0x200, deepFlag = 0x800, multipartFlag = 0x1000;
    const auto version = readLe(bytes, 4, 4);
    if (!version)
        return failed(ImageFormat::OpenExr, "truncated OpenEXR: it ends inside the version field");
    std::size_t at = 8;
    std::optional<std::array<std::int64_t, 4>> window;
    std::optional<unsigned> compression;
    const auto readString = [&](std::string& out) {
        const std::size_t start = at;
        while (at < bytes.size() && bytes[at] != 0)
            ++at;
        if (at >= bytes.size() || at - start > 255)
            return false;
        out.assign(reinterpret_cast<const char*>(bytes.data() + start), at - start);
        ++at;
        return true;
    };
    while (true) {
        std::string name, type;
        if (!readString(name))
            return failed(ImageFormat::OpenExr, "truncated OpenEXR: it ends inside the header");
        if (name.empty())
            break;
        if (!readString(type))
            return failed(ImageFormat::OpenExr, "truncated OpenEXR: it ends inside the header");
        const auto size = readLe(bytes, at, 4);
        if (!size || asSigned32(*size) < 0 || at + 4 + *size > bytes.size())
            return failed(ImageFormat::OpenExr, fmt::format("truncated OpenEXR: it ends inside attribute '{}'", name));
        at += 4;
        // OpenEXR goes on after a value of a type it knows from where its content ends, not from
        // where the size says: a channel list whose size disagreed with its names had it read
        // another dataWindow further on than this walk did (a fuzzed file: 8x65542 here, 8x6
        // decoded). Refusing such a value keeps both walks in step.
        if (const auto content = exrValueBytes(type, bytes, at); content && *content != *size)
            return failed(ImageFormat::OpenExr,
                          fmt::format("corrupt OpenEXR: attribute '{}' of type '{}' holds {} bytes, its size says {}",
                                      printable(name), printable(type), *content, *size));
        // OpenEXR keeps the last of repeated attributes; refusing repeats keeps both readers of
        // the size in agreement.
        if (name == "dataWindow" || name == "compression") {
            if ((name == "dataWindow" && window) || (name == "compression" && compression))
                return failed(ImageFormat::OpenExr, fmt::format("corrupt OpenEXR: attribute '{}' is repeated", name));
            // Their sizes are their types' (checked above).
            if (name == "dataWindow" && type == "box2i")
                window = std::array<std::int64_t, 4>{
                    asSigned32(*readLe(bytes, at, 4)), asSigned32(*readLe(bytes, at + 4, 4)),
                    asSigned32(*readLe(bytes, at + 8, 4)), asSigned32(*readLe(bytes, at + 12, 4))};
            else if (name == "compression" && type == "compression")
                compression = bytes[at];
            else
                return failed(ImageFormat::OpenExr, fmt::format("corrupt OpenEXR: attribute '{}' of type '{}'", name, type));
        }
        at += static_cast<std::size_t>(*size);
    }
    if (!window)
        return failed(ImageFormat::OpenExr, "corrupt OpenEXR: no dataWindow attribute");
    const std::int64_t width = (*window)[2] - (*window)[0] + 1;
    const std::int64_t height = (*window)[3] - (*window)[1] + 1;
    if (width <= 0 || height <= 0)
        return failed(ImageFormat::OpenExr, fmt::format("corrupt OpenEXR: data window of {}x{}", width, height));
    ImageHeader header = sized(ImageFormat::OpenExr, static_cast<std::uint64_t>(width), static_cast<std::uint64_t>(height));
    if ((*version & (tiledFlag | deepFlag | multipartFlag)) != 0 || !compression)
        return header;
    // Scan lines per chunk for NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB.
    static constexpr std::array<std::uint64_t, 10> linesPerChunk = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    if (*compression >= linesPerChunk.size())
        return header;
    const std::uint64_t chunks = (header.height + linesPerChunk[*compression] - 1) / linesPerChunk[*compression];
    for (std::uint64_t i = 0; i < chunks; ++i) {
        const auto offset = readLe(bytes, at + static_cast<std::size_t>(i) * 8, 8);
        const auto dataSize = offset && *offset <= bytes.size() ? readLe(bytes, static_cast<std::size_t>(*offset) + 4, 4)
                                                                : std::nullopt;
        if (!dataSize || *offset + 8 + *dataSize > bytes.size())
            return failed(ImageFormat::OpenExr, fmt::format("truncated OpenEXR: the file ends at byte {}, before "
                                                            "scan-line chunk {} of {}",
                                                            bytes.size(), i + 1, chunks));
    }
    return header;
}

} // namespace

std::string_view formatName(ImageFormat format)
{
    switch (format) {
    case ImageFormat::Png:
        return "PNG";
    case ImageFormat::Jpeg:
        return "JPEG";
    case ImageFormat::Tiff:
        return "TIFF";
    case ImageFormat::Bmp:
        return "BMP";
    case ImageFormat::WebP:
        return "WebP";
    case ImageFormat::OpenExr:
        return "OpenEXR";
    }
    return "?";
}

ImageHeader readImageHeader(Bytes bytes)
{
    if (startsWith(bytes, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}))
        return readPng(bytes);
    if (startsWith(bytes, {0xff, 0xd8, 0xff}))
        return readJpeg(bytes);
    if (startsWith(bytes, {'I', 'I', 42, 0}) || startsWith(bytes, {'M', 'M', 0, 42}) ||
        startsWith(bytes, {'I', 'I', 43, 0}) || startsWith(bytes, {'M', 'M', 0, 43}))
        return readTiff(bytes);
    if (startsWith(bytes, {'B', 'M'}))
        return readBmp(bytes);
    if (startsWith(bytes, {'R', 'I', 'F', 'F'}) && bytes.size() >= 12 && startsWith(bytes.subspan(8), {'W', 'E', 'B', 'P'}))
        return readWebP(bytes);
    if (startsWith(bytes, {0x76, 0x2f, 0x31, 0x01}))
        return readExr(bytes);
    return failed(ImageFormat::Png, bytes.empty() ? "the file is empty"
                                                  : "not a PNG, JPEG, TIFF, BMP, WebP or OpenEXR image "
                                                    "(unknown signature)");
}

} // namespace defocus
