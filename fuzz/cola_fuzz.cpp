// libFuzzer target for the CoLa telegram decoder: the stream decoder (both dialects, input cut into
// pieces the fuzzer chooses), the telegram split and the LMDscandata decoder. Anything decoded must
// encode again and decode to the same bytes; a mismatch aborts (a finding), as does any crash or
// sanitizer report. Built and run by scripts/fuzz.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "acquisition/cola.hpp"
#include "acquisition/scan_data.hpp"

namespace {

void checkPayload(const std::string& payload, sailshape::ColaDialect dialect) {
  try {
    const sailshape::ColaTelegram t = sailshape::splitColaTelegram(payload);
    if (sailshape::joinColaTelegram(t) != payload && t.type != "sFA") std::abort();
  } catch (const sailshape::ColaError&) {
  }
  if (!sailshape::isScanDataTelegram(payload)) return;
  sailshape::ScanData scan;
  try {
    scan = sailshape::decodeScanData(payload, dialect);
  } catch (const sailshape::ColaError&) {
    return;
  }
  // A decoded scan re-encodes to a payload that decodes to the same encoding.
  const std::string again = sailshape::encodeScanData(scan, dialect);
  const std::string twice = sailshape::encodeScanData(sailshape::decodeScanData(again, dialect), dialect);
  if (again != twice) std::abort();
  if (dialect == sailshape::ColaDialect::kBinary && again != payload) std::abort();
  try {
    (void)sailshape::frameCola(dialect, again);
  } catch (const sailshape::ColaError&) {
    // Only a payload over the size limit, or (CoLa A) one whose texts hold STX/ETX, may be refused.
    const bool control = dialect == sailshape::ColaDialect::kAscii &&
                         again.find_first_of(std::string_view("\x02\x03", 2)) != std::string::npos;
    if (again.size() <= sailshape::kColaMaxPayloadBytes && !control) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  // First byte: dialect (bit 0) and the size of the pieces fed to the decoder (1..128 bytes).
  const auto dialect = (data[0] & 1) ? sailshape::ColaDialect::kAscii : sailshape::ColaDialect::kBinary;
  const size_t piece = static_cast<size_t>(data[0] >> 1) + 1;
  const std::string_view input(reinterpret_cast<const char*>(data + 1), size - 1);

  sailshape::ColaStreamDecoder decoder({dialect, 16 * 1024});
  size_t returned_bytes = 0;
  for (size_t at = 0; at < input.size(); at += piece) {
    decoder.feed(input.substr(at, piece));
    while (auto payload = decoder.next()) {
      returned_bytes += payload->size();
      checkPayload(*payload, dialect);
    }
  }
  // Nothing invented: frames returned plus bytes held never exceed what was fed.
  if (returned_bytes + decoder.bufferedBytes() > input.size()) std::abort();
  // The payload decoders must also survive the raw input directly.
  checkPayload(std::string(input), dialect);
  return 0;
}
