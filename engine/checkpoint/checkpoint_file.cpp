// Atomic writes and mapped reads of checkpoint files (see checkpoint.hpp).
#include <fcntl.h>  // sync_file_range (_GNU_SOURCE, which g++ defines)
#include <fmt/core.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void refuse_io(const std::string& what, const std::string& path) {
  throw IoError(fmt::format("cannot {} '{}': {}", what, path, std::strerror(errno)));
}

void sync_directory_of(const fs::path& path) {
  const auto dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;  // best effort: the rename itself is already atomic
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), tmp_(path_ + ".tmp") {
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) refuse_io("create", tmp_);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) ::unlink(tmp_.c_str());
}

void AtomicFile::write(std::span<const std::byte> bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const auto n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) refuse_io("write", tmp_);
    done += static_cast<std::size_t>(n);
  }
  // The disk starts on what is written while the writer prepares the rest, so the fsync of
  // sync() waits for less (a hint: an error shows at the fsync).
  const auto from = static_cast<off_t>(written_);
  written_ += bytes.size();
  if (bytes.size() >= kStartWriteback)
    ::sync_file_range(fd_, from, static_cast<off_t>(bytes.size()), SYNC_FILE_RANGE_WRITE);
}

void AtomicFile::write_at(std::size_t offset, std::span<const std::byte> bytes) {
  if (::pwrite(fd_, bytes.data(), bytes.size(), static_cast<off_t>(offset)) !=
      static_cast<ssize_t>(bytes.size()))
    refuse_io("write", tmp_);
}

void AtomicFile::sync() {
  if (synced_) return;
  const int fd = fd_;
  fd_ = -1;
  synced_ = true;
  if (::fsync(fd) != 0) {
    ::close(fd);
    refuse_io("flush", tmp_);
  }
  if (::close(fd) != 0) refuse_io("close", tmp_);
}

void AtomicFile::commit(const std::string& previous) {
  sync();
  std::error_code ec;
  if (!previous.empty() && fs::exists(path_, ec)) {
    fs::remove(previous, ec);
    fs::create_hard_link(path_, previous, ec);
    if (ec) fs::copy_file(path_, previous, fs::copy_options::overwrite_existing, ec);
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) refuse_io("rename onto", path_);
  committed_ = true;
  sync_directory_of(path_);
}

void write_file_atomically(const std::string& path, std::span<const std::byte> bytes,
                           const std::string& previous) {
  AtomicFile file(path);
  file.write(bytes);
  file.commit(previous);
}

MappedFile::MappedFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat info = {};
  if (fd < 0 || ::fstat(fd, &info) != 0) {
    if (fd >= 0) ::close(fd);
    throw InputError(fmt::format("{}: cannot open the checkpoint: {}", path, std::strerror(errno)));
  }
  size_ = static_cast<std::size_t>(info.st_size);
  if (size_ > 0) {
    void* at = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (at == MAP_FAILED) {
      ::close(fd);
      throw InputError(
          fmt::format("{}: cannot read the checkpoint: {}", path, std::strerror(errno)));
    }
    data_ = static_cast<const std::byte*>(at);
  }
  ::close(fd);
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
}

}  // namespace dhpd
