#include "dynorb/synth/png_writer.h"

#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace dynorb::synth {
namespace {

void PutU32(std::string* out, uint32_t v) {
  const char bytes[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                         static_cast<char>(v >> 8), static_cast<char>(v)};
  out->append(bytes, 4);
}

void PutChunk(std::string* out, const char* type, const std::string& data) {
  PutU32(out, static_cast<uint32_t>(data.size()));
  const size_t start = out->size();
  out->append(type, 4);
  out->append(data);
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(out->data() + start),
                          static_cast<uInt>(out->size() - start));
  PutU32(out, static_cast<uint32_t>(crc));
}

}  // namespace

std::string EncodePng(const cv::Mat& image) {
  CV_Assert(image.type() == CV_8UC3 || image.type() == CV_8UC1 || image.type() == CV_16UC1);
  const int w = image.cols, h = image.rows;
  const int channels = image.channels();
  const int bytes_per_sample = image.depth() == CV_16U ? 2 : 1;
  const int bpp = channels * bytes_per_sample;  // bytes per pixel
  const size_t row_bytes = static_cast<size_t>(w) * bpp;

  // Raw scanlines: filter byte 1 (Sub) then the differences to the pixel on the left.
  std::vector<uint8_t> raw((row_bytes + 1) * h);
  std::vector<uint8_t> line(row_bytes);
  for (int y = 0; y < h; ++y) {
    if (image.type() == CV_8UC3) {
      const uint8_t* p = image.ptr<uint8_t>(y);
      for (int x = 0; x < w; ++x) {
        line[3 * x] = p[3 * x + 2];
        line[3 * x + 1] = p[3 * x + 1];
        line[3 * x + 2] = p[3 * x];
      }
    } else if (image.type() == CV_16UC1) {
      const uint16_t* p = image.ptr<uint16_t>(y);
      for (int x = 0; x < w; ++x) {
        line[2 * x] = static_cast<uint8_t>(p[x] >> 8);
        line[2 * x + 1] = static_cast<uint8_t>(p[x] & 0xFF);
      }
    } else {
      const uint8_t* p = image.ptr<uint8_t>(y);
      std::copy(p, p + w, line.begin());
    }
    uint8_t* out = raw.data() + y * (row_bytes + 1);
    out[0] = 1;
    for (int i = 0; i < bpp; ++i) out[1 + i] = line[i];
    for (size_t i = bpp; i < row_bytes; ++i)
      out[1 + i] = static_cast<uint8_t>(line[i] - line[i - bpp]);
  }

  z_stream z{};
  if (deflateInit2(&z, 1, Z_DEFLATED, 15, 8, Z_RLE) != Z_OK)
    throw std::runtime_error("deflateInit2 failed");
  std::string compressed(deflateBound(&z, static_cast<uLong>(raw.size())), '\0');
  z.next_in = raw.data();
  z.avail_in = static_cast<uInt>(raw.size());
  z.next_out = reinterpret_cast<Bytef*>(compressed.data());
  z.avail_out = static_cast<uInt>(compressed.size());
  const int status = deflate(&z, Z_FINISH);
  compressed.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw std::runtime_error("deflate failed");

  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  PutU32(&header, static_cast<uint32_t>(w));
  PutU32(&header, static_cast<uint32_t>(h));
  header.push_back(static_cast<char>(8 * bytes_per_sample));   // bit depth
  header.push_back(static_cast<char>(channels == 3 ? 2 : 0));  // colour type: RGB or grey
  header.append(3, '\0');  // deflate, adaptive filters, no interlace
  PutChunk(&png, "IHDR", header);
  PutChunk(&png, "IDAT", compressed);
  PutChunk(&png, "IEND", "");
  return png;
}

}  // namespace dynorb::synth
