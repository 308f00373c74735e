#pragma once
// HMAC-SHA256 authentication of DISPLAY_COMMAND messages (threat model: display/README.md).
//
// A signed message is the encoded lcmt_display_command followed by a 32-byte tag:
//   bytes = payload || HMAC-SHA256(key, payload)
// The payload holds utime and sequence, so the tag covers them; the driver rejects a tag
// that does not match (unsigned or forged) and a (utime, sequence) not newer than the last
// accepted one (replayed). OpenSSL's libcrypto (Debian libssl-dev) computes the HMAC: it is
// already on every Debian machine that has the toolchain, is FIPS-reviewed, and offers a
// constant-time compare (CRYPTO_memcmp); libsodium's crypto_auth_hmacsha256 would do the
// same but is one more package.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sedbridge::display {

class CommandAuthenticator {
 public:
  static constexpr std::size_t kTagBytes = 32;   ///< HMAC-SHA256 output
  static constexpr std::size_t kMinKeyBytes = 32;  ///< as long as the hash: no weaker key

  /// @param[in] key  secret, at least kMinKeyBytes bytes; std::invalid_argument otherwise
  explicit CommandAuthenticator(std::vector<uint8_t> key);

  /// Reads the key from `path`: its raw bytes (e.g. `head -c 32 /dev/urandom > key`), at
  /// least kMinKeyBytes. Throws std::runtime_error when it cannot be read, is too short, or
  /// is readable by group or others (a key others can read authenticates nothing).
  static CommandAuthenticator FromKeyFile(const std::string& path);

  /// payload || tag.
  std::vector<uint8_t> Sign(const void* payload, std::size_t size) const;

  /// The payload's length when `data` ends in the right tag for the bytes before it;
  /// std::nullopt for a short message or a wrong tag (compared in constant time).
  std::optional<std::size_t> Verify(const void* data, std::size_t size) const;

 private:
  void Tag(const uint8_t* payload, std::size_t size, uint8_t out[kTagBytes]) const;
  std::vector<uint8_t> key_;
};

}  // namespace sedbridge::display
