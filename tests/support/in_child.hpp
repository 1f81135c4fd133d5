#pragma once
// Runs a function in a forked child process and returns what it wrote, so that a third-party
// reader which dies on a malformed file (assimp 5.2's PLY and glTF readers read out of bounds
// on some, found by tests/fuzz/fuzz_load_*) ends the child, not the caller. The child inherits
// the caller's memory copy-on-write, restores the default action of the crash signals, writes
// its result as bytes through a pipe and exits without cleanup; one that hangs is killed after a
// time limit. POSIX only (fork, pipe, poll).
// Cost: one fork and a copy of the result; the result's bytes are held twice at the end.
#include <chrono>
#include <cstddef>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace infolerp::support {

// Values as bytes, in the order they are put; vectors and strings with their length first.
class byte_writer {
 public:
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <class T>
  void put(const std::vector<T>& v) {
    put(v.size());
    if (v.empty()) return;
    const auto* p = reinterpret_cast<const char*>(v.data());
    bytes_.insert(bytes_.end(), p, p + v.size() * sizeof(T));
  }
  void put(const std::string& s) {
    put(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  const std::vector<char>& bytes() const { return bytes_; }

 private:
  std::vector<char> bytes_;
};

// The reverse of byte_writer; good() turns false (and stays) when the bytes run out, complete()
// says that every byte was read and none was missing.
class byte_reader {
 public:
  explicit byte_reader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void get(T& v) {
    if (take(sizeof(T))) std::memcpy(&v, bytes_.data() + at_ - sizeof(T), sizeof(T));
  }
  template <class T>
  void get(std::vector<T>& v) {
    std::size_t n = 0;
    get(n);
    if (!ok_ || n > (bytes_.size() - at_) / sizeof(T)) return void(ok_ = false);
    v.resize(n);
    if (take(n * sizeof(T)) && n > 0) std::memcpy(v.data(), bytes_.data() + at_ - n * sizeof(T), n * sizeof(T));
  }
  void get(std::string& s) {
    std::vector<char> chars;
    get(chars);
    s.assign(chars.begin(), chars.end());
  }
  bool good() const { return ok_; }
  bool complete() const { return ok_ && at_ == bytes_.size(); }

 private:
  bool take(std::size_t n) {
    ok_ = ok_ && n <= bytes_.size() - at_;
    at_ += ok_ ? n : 0;
    return ok_;
  }
  const std::vector<char>& bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

struct child_result {
  std::vector<char> bytes;  // all the child wrote
  bool completed = false;   // it exited normally with status 0
  std::string death;        // otherwise: how it ended ("Segmentation fault", "exit status 3", ...)
};

// Runs work(writer) in a child; returns the writer's bytes once the child has ended, or kills it
// when it has not finished within `limit` (a reader caught in a loop). When no child can be made
// (fork or pipe fails), runs work here.
child_result run_in_child(const std::function<void(byte_writer&)>& work, std::chrono::milliseconds limit);

}  // namespace infolerp::support
