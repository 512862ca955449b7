#include "tests/firmware/codecs/jpeg_test_util.h"

#include <dirent.h>
#include <stdlib.h>
#include <sys/wait.h>

// clang-format off
#include <cstdio>
#include <jpeglib.h>
// clang-format on

#include <cmath>
#include <csetjmp>

#include "tests/support/remove_tree.h"

namespace lb::test {

ConstPlanarU8 Ycc420::View() const { return Strip(0, height); }

ConstPlanarU8 Ycc420::Strip(int32_t y0, int32_t rows) const {
  ConstPlanarU8 v;
  v.count = 3;
  v.planes[0] = {y.data() + static_cast<size_t>(y0) * width, width, rows, 1, width};
  const int32_t crows = (rows + 1) / 2;
  const size_t coff = static_cast<size_t>(y0 / 2) * cwidth();
  v.planes[1] = {cb.data() + coff, cwidth(), crows, 1, cwidth()};
  v.planes[2] = {cr.data() + coff, cwidth(), crows, 1, cwidth()};
  return v;
}

Ycc420 MakeTexture(int32_t width, int32_t height) {
  Ycc420 img;
  img.width = width;
  img.height = height;
  img.y.resize(static_cast<size_t>(width) * height);
  img.cb.resize(static_cast<size_t>(img.cwidth()) * img.cheight());
  img.cr.resize(img.cb.size());
  for (int32_t yy = 0; yy < height; ++yy) {
    for (int32_t x = 0; x < width; ++x) {
      // A slow ripple and a fine one: a strip fed one row off or out of order shows up.
      const double v = 40 + 120.0 * (x + yy) / (width + height) +
                       25 * std::sin(x * 0.21) * std::cos(yy * 0.17) +
                       20 * std::sin(x * 0.7 + yy * 1.3);
      img.y[static_cast<size_t>(yy) * width + x] = static_cast<uint8_t>(std::lround(v));
    }
  }
  for (int32_t yy = 0; yy < img.cheight(); ++yy) {
    for (int32_t x = 0; x < img.cwidth(); ++x) {
      const size_t i = static_cast<size_t>(yy) * img.cwidth() + x;
      img.cb[i] = static_cast<uint8_t>(100 + 50 * x / (img.cwidth() + 1) + 15 * std::sin(yy * 1.1));
      img.cr[i] =
          static_cast<uint8_t>(150 - 40 * yy / (img.cheight() + 1) + 15 * std::cos(x * 0.9));
    }
  }
  return img;
}

namespace {
struct DecodeError {
  jpeg_error_mgr mgr;
  jmp_buf jump;
};
[[noreturn]] void OnDecodeError(j_common_ptr cinfo) {
  longjmp(reinterpret_cast<DecodeError*>(cinfo->err)->jump, 1);
}
}  // namespace

bool DecodeYcc(const std::vector<uint8_t>& jpeg, int32_t* width, int32_t* height,
               std::vector<uint8_t>* ycc, std::string* error) {
  jpeg_decompress_struct cinfo;
  DecodeError err;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = OnDecodeError;
  if (setjmp(err.jump) != 0) {
    char text[JMSG_LENGTH_MAX];
    (*err.mgr.format_message)(reinterpret_cast<j_common_ptr>(&cinfo), text);
    *error = text;
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, jpeg.data(), static_cast<unsigned long>(jpeg.size()));
  jpeg_read_header(&cinfo, TRUE);
  cinfo.out_color_space = JCS_YCbCr;
  cinfo.do_fancy_upsampling = FALSE;  // chroma by repetition, like PlanePsnr's reference
  jpeg_start_decompress(&cinfo);
  *width = static_cast<int32_t>(cinfo.output_width);
  *height = static_cast<int32_t>(cinfo.output_height);
  ycc->assign(static_cast<size_t>(cinfo.output_width) * cinfo.output_height * 3, 0);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row =
        ycc->data() + static_cast<size_t>(cinfo.output_scanline) * cinfo.output_width * 3;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

double PlanePsnr(const Ycc420& src, const std::vector<uint8_t>& ycc, int c) {
  double sse = 0;
  for (int32_t y = 0; y < src.height; ++y) {
    for (int32_t x = 0; x < src.width; ++x) {
      int ref;
      if (c == 0) {
        ref = src.y[static_cast<size_t>(y) * src.width + x];
      } else {
        const auto& plane = c == 1 ? src.cb : src.cr;
        ref = plane[static_cast<size_t>(y / 2) * src.cwidth() + x / 2];
      }
      const double d = ref - ycc[(static_cast<size_t>(y) * src.width + x) * 3 + c];
      sse += d * d;
    }
  }
  const double mse = sse / (static_cast<double>(src.width) * src.height);
  return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::vector<uint8_t> ReadFile(const std::string& path) {
  std::vector<uint8_t> out;
  FILE* f = fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  uint8_t buf[65536];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), f)) > 0) out.insert(out.end(), buf, buf + n);
  fclose(f);
  return out;
}

ScratchDir::ScratchDir() {
  char tmpl[] = "/tmp/lb_jpeg_XXXXXX";
  if (mkdtemp(tmpl) != nullptr) dir_ = tmpl;
}

// Without a shell (RemoveTree): under qemu-user, the child of a fork right after a test's threads
// ended once hung on a lock (the aarch64 daemon test, in CI), and the whole run with it.
ScratchDir::~ScratchDir() {
  if (dir_.empty()) return;
  if (!RemoveTree(dir_)) fprintf(stderr, "could not remove %s\n", dir_.c_str());
}

std::vector<std::string> ScratchDir::Entries() const {
  std::vector<std::string> names;
  DIR* d = opendir(dir_.c_str());
  if (d == nullptr) return names;
  while (dirent* e = readdir(d)) {
    const std::string n = e->d_name;
    if (n != "." && n != "..") names.push_back(n);
  }
  closedir(d);
  return names;
}

bool HaveTool(const char* name) {
  const std::string cmd = std::string("command -v ") + name + " >/dev/null 2>&1";
  return system(cmd.c_str()) == 0;
}

std::string RunTool(const std::string& command, int* exit_code) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (p == nullptr) {
    *exit_code = -1;
    return out;
  }
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

}  // namespace lb::test
