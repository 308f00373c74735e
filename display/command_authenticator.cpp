#include "display/command_authenticator.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace sedbridge::display {

CommandAuthenticator::CommandAuthenticator(std::vector<uint8_t> key) : key_(std::move(key)) {
  if (key_.size() < kMinKeyBytes)
    throw std::invalid_argument("HMAC key must have at least " + std::to_string(kMinKeyBytes) + " bytes (has " +
                                std::to_string(key_.size()) + ")");
}

CommandAuthenticator CommandAuthenticator::FromKeyFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error("cannot read key file '" + path + "'");
  if (!S_ISREG(st.st_mode)) throw std::runtime_error("key file '" + path + "' is not a regular file");
  if (st.st_mode & (S_IRWXG | S_IRWXO))
    throw std::runtime_error("key file '" + path + "' is accessible by group or others (chmod 600 it)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read key file '" + path + "'");
  std::vector<uint8_t> key((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (key.size() < kMinKeyBytes)
    throw std::runtime_error("key file '" + path + "' has " + std::to_string(key.size()) + " bytes; at least " +
                             std::to_string(kMinKeyBytes) + " needed (head -c 32 /dev/urandom > KEY)");
  return CommandAuthenticator(std::move(key));
}

void CommandAuthenticator::Tag(const uint8_t* payload, std::size_t size, uint8_t out[kTagBytes]) const {
  unsigned int len = 0;
  if (!HMAC(EVP_sha256(), key_.data(), static_cast<int>(key_.size()), payload, size, out, &len) || len != kTagBytes)
    throw std::runtime_error("HMAC-SHA256 failed");
}

std::vector<uint8_t> CommandAuthenticator::Sign(const void* payload, std::size_t size) const {
  const auto* p = static_cast<const uint8_t*>(payload);
  std::vector<uint8_t> out(p, p + size);
  out.resize(size + kTagBytes);
  Tag(p, size, out.data() + size);
  return out;
}

std::optional<std::size_t> CommandAuthenticator::Verify(const void* data, std::size_t size) const {
  if (data == nullptr || size < kTagBytes) return std::nullopt;
  const auto* p = static_cast<const uint8_t*>(data);
  const std::size_t n = size - kTagBytes;
  uint8_t expected[kTagBytes];
  try {
    Tag(p, n, expected);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (CRYPTO_memcmp(expected, p + n, kTagBytes) != 0) return std::nullopt;
  return n;
}

}  // namespace sedbridge::display
