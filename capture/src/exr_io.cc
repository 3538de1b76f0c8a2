#include "exr_io.h"

#include <algorithm>
#include <system_error>

#include "calf/format/files.h"
#include "image_input.h"

namespace calf::capture::detail {

namespace {

// OIIO keeps a per-thread error string; fetch it so that it does not leak into a later message.
std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  return e.empty() ? fallback : e;
}

}  // namespace

Status write_exr(const std::filesystem::path& path, uint32_t width, uint32_t height,
                 const std::vector<ExrChannelOut>& channels) {
  const std::string final_name = path.string();
  // The output rules, temporary name and cleanup on a signal are files::TempFile's.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(final_name));
  temp.close_fd();  // OIIO opens the file by name
  const std::string& temp_name = temp.temp_path();
  const size_t nch = channels.size();
  const size_t pixels = static_cast<size_t>(width) * height;
  // Interleave once: OIIO converts float to each channel's own format while writing.
  std::vector<float> interleaved(pixels * nch);
  for (size_t c = 0; c < nch; ++c) {
    const float* src = channels[c].data;
    for (size_t i = 0; i < pixels; ++i) interleaved[i * nch + c] = src[i * channels[c].stride];
  }
  try {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("exr");
    if (!out) {
      return Status(ErrorId::kFileWrite, final_name + ": " + oiio_error("no OpenEXR writer"));
    }
    OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), static_cast<int>(nch),
                         OIIO::TypeDesc::HALF);
    spec.channelnames.clear();
    spec.channelformats.clear();
    for (const ExrChannelOut& ch : channels) {
      spec.channelnames.emplace_back(ch.name);
      spec.channelformats.push_back(ch.half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    }
    spec.alpha_channel = -1;
    spec.z_channel = -1;
    spec.attribute("compression", "zip");
    // OIIO stamps the current time into the EXR header (capDate) unless DateTime is set; an empty
    // one keeps the bytes a function of the pixels only (deterministic output, DESIGN.md).
    spec.attribute("DateTime", "");
    if (!out->open(temp_name, spec)) {
      std::string e = out->geterror();
      return Status(ErrorId::kFileWrite, final_name + ": " + (e.empty() ? "cannot open" : e));
    }
    bool ok = out->write_image(OIIO::TypeDesc::FLOAT, interleaved.data());
    std::string e = ok ? "" : out->geterror();
    ok = out->close() && ok;
    if (!ok) {
      return Status(ErrorId::kFileWrite, final_name + ": " + (e.empty() ? "write failed" : e));
    }
  } catch (const std::exception& ex) {
    return Status(ErrorId::kFileWrite, final_name + ": " + ex.what());
  }
  return temp.commit(/*sync=*/false);
}

Expected<ExrReader> ExrReader::open(const std::filesystem::path& path) {
  // Missing is E135; a directory or FIFO under an image's name is E002 "not a regular file".
  if (Status s = files::check_regular_file(path.string()); !s.ok()) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      return Status(ErrorId::kCaptureFileMissing, path.string() + ": no such file");
    }
    return s;
  }
  ExrReader r;
  r.path_ = path.string();
  // Only the OpenEXR reader ever sees the bytes, and only after its header passed
  // check_exr_header: OIIO's open() would hand a file that is not EXR to whichever of its format
  // plugins claims it (a PNG named .exr reached libpng, which printed its own stderr line).
  ExrHeader header;
  CALF_RETURN_IF_ERROR(check_exr_header(path, ErrorId::kCaptureImageFormat, &header));
  try {
    r.input_ = OIIO::ImageInput::create("openexr");
    if (r.input_) {
      OIIO::ImageSpec spec;
      if (!r.input_->open(r.path_, spec)) r.input_.reset();
    }
    if (!r.input_) {
      return Status(ErrorId::kCaptureImageFormat,
                    r.path_ + ": not a readable image: " + oiio_error("unknown format"));
    }
    const OIIO::ImageSpec& spec = r.input_->spec();
    if (spec.deep || spec.depth != 1 || spec.width <= 0 || spec.height <= 0) {
      return Status(ErrorId::kCaptureImageFormat,
                    r.path_ + ": not a flat 2-D image (deep or volume data)");
    }
    r.width_ = static_cast<uint32_t>(spec.width);
    r.height_ = static_cast<uint32_t>(spec.height);
    r.names_ = spec.channelnames;
    for (int c = 0; c < spec.nchannels; ++c) r.formats_.push_back(spec.channelformat(c));
    r.names_.resize(static_cast<size_t>(std::max(0, spec.nchannels)));
  } catch (const std::exception& e) {
    return Status(ErrorId::kCaptureImageFormat, r.path_ + ": " + e.what());
  }
  return r;
}

int ExrReader::channel(const std::string& name) const {
  for (size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

Status ExrReader::require_float(int index) const {
  const OIIO::TypeDesc t = formats_[static_cast<size_t>(index)];
  if (t == OIIO::TypeDesc::HALF || t == OIIO::TypeDesc::FLOAT) return Status::Ok();
  return Status(ErrorId::kCaptureImageFormat,
                path_ + ": channel '" + names_[static_cast<size_t>(index)] + "' has pixel type " +
                    t.c_str() + ", expected half or float");
}

Status ExrReader::read_rows(uint32_t y0, uint32_t y1, std::vector<float>* out) {
  const size_t nch = names_.size();
  const auto rows_error = [&](const std::string& why) {
    return Status(ErrorId::kCaptureImageFormat,
                  path_ + ": rows " + std::to_string(y0) + ".." + std::to_string(y1) + " " + why);
  };
  if (y0 >= y1 || y1 > height_) return rows_error("are outside the image");
  const size_t rows = y1 - y0;
  out->resize(rows * width_ * nch);
  // The rows are read in the file's own channel types and converted here, channel by channel:
  // OIIO 2.4's converting read_scanlines allocates a 64 MiB staging buffer on every call
  // whatever the rows asked for, which under AddressSanitizer (a fresh mapping, its shadow
  // poisoned, unmapped when it leaves the quarantine) was most of a sanitized encode's time.
  size_t pixel_bytes = 0;
  for (const OIIO::TypeDesc& t : formats_) pixel_bytes += t.size();
  native_.resize(rows * width_ * pixel_bytes);
  try {
    const OIIO::ImageSpec& spec = input_->spec();
    if (!input_->read_native_scanlines(0, 0, spec.y + static_cast<int>(y0),
                                       spec.y + static_cast<int>(y1), 0, 0, static_cast<int>(nch),
                                       native_.data())) {
      std::string e = input_->geterror();
      return rows_error("cannot be decoded: " + (e.empty() ? "truncated or corrupt" : e));
    }
    const auto px = static_cast<OIIO::stride_t>(pixel_bytes);
    const auto out_px = static_cast<OIIO::stride_t>(nch * sizeof(float));
    size_t offset = 0;
    for (size_t c = 0; c < nch; ++c) {
      if (!OIIO::convert_image(1, static_cast<int>(width_), static_cast<int>(rows), 1,
                               native_.data() + offset, formats_[c], px, px * width_,
                               OIIO::AutoStride, out->data() + c, OIIO::TypeDesc::FLOAT, out_px,
                               out_px * width_, OIIO::AutoStride)) {
        return rows_error("cannot be converted from " + std::string(formats_[c].c_str()) +
                          " in channel '" + names_[c] + "'");
      }
      offset += formats_[c].size();
    }
  } catch (const std::exception& e) {
    return Status(ErrorId::kCaptureImageFormat, path_ + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace calf::capture::detail
