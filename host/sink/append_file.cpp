#include "sink/append_file.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "scene/error.h"

namespace portalsim {

namespace {
uint32_t crc_update(uint32_t crc, const char* p, size_t n) {
  while (n > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = static_cast<uint32_t>(::crc32(crc, reinterpret_cast<const Bytef*>(p), chunk));
    p += chunk;
    n -= chunk;
  }
  return crc;
}
}  // namespace

AppendFile::AppendFile(const std::string& dir, const std::string& name, const FileState* resume)
    : dir_(dir),
      partial_((std::filesystem::path(dir) / (name + ".partial")).string()),
      final_((std::filesystem::path(dir) / name).string()) {
  state_.name = name;
  if (resume) {
    fd_ = ::open(partial_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0) throw OutputError(partial_ + ": cannot resume: " + std::strerror(errno));
    const off_t size = ::lseek(fd_, 0, SEEK_END);
    if (size < 0 || static_cast<uint64_t>(size) < resume->bytes)
      throw OutputError(partial_ + ": shorter than the checkpoint says (" + std::to_string(size) + " < " +
                        std::to_string(resume->bytes) + " bytes); the run cannot be resumed, start it again");
    if (::ftruncate(fd_, static_cast<off_t>(resume->bytes)) != 0 ||
        ::lseek(fd_, static_cast<off_t>(resume->bytes), SEEK_SET) < 0)
      throw OutputError(partial_ + ": cannot truncate for resume: " + std::strerror(errno));
    state_.bytes = resume->bytes;
    state_.crc32 = resume->crc32;
  } else {
    fd_ = ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw OutputError(partial_ + ": cannot create: " + std::strerror(errno));
    state_.crc32 = static_cast<uint32_t>(::crc32(0, nullptr, 0));
  }
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendFile::append(std::string_view data) {
  const char* p = data.data();
  size_t left = data.size();
  while (left > 0) {
    const ssize_t w = ::write(fd_, p, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw OutputError(partial_ + ": write failed: " + std::strerror(errno));
    }
    p += w;
    left -= static_cast<size_t>(w);
  }
  state_.crc32 = crc_update(state_.crc32, data.data(), data.size());
  state_.bytes += data.size();
}

void AppendFile::overwrite(uint64_t offset, std::string_view data) {
  if (::pwrite(fd_, data.data(), data.size(), static_cast<off_t>(offset)) != static_cast<ssize_t>(data.size()))
    throw OutputError(partial_ + ": write failed: " + std::strerror(errno));
}

void AppendFile::recompute_crc() {
  const int fd = ::open(partial_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(partial_ + ": cannot read back: " + std::strerror(errno));
  std::vector<char> buf(1 << 20);
  uint32_t crc = static_cast<uint32_t>(::crc32(0, nullptr, 0));
  ssize_t r;
  while ((r = ::read(fd, buf.data(), buf.size())) > 0) crc = crc_update(crc, buf.data(), static_cast<size_t>(r));
  ::close(fd);
  if (r < 0) throw OutputError(partial_ + ": cannot read back: " + std::strerror(errno));
  state_.crc32 = crc;
}

void AppendFile::finish() {
  if (fd_ >= 0) {
    if (::fsync(fd_) != 0) throw OutputError(partial_ + ": fsync failed: " + std::strerror(errno));
    ::close(fd_);
    fd_ = -1;
  }
  std::error_code ec;
  std::filesystem::rename(partial_, final_, ec);
  if (ec) throw OutputError(final_ + ": cannot move into place: " + ec.message());
}

}  // namespace portalsim
