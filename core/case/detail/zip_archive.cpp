#include "case/detail/zip_archive.hpp"

#include <zip.h>

namespace viscera::vcase::detail {
namespace {

constexpr uint32_t kUnixRegularFile0644 = 0100644;
constexpr uint16_t kDosDate1980Jan1 = (0 << 9) | (1 << 5) | 1; // year-1980, month, day
constexpr uint16_t kDosTimeMidnight = 0;
constexpr uint32_t kDosDirectoryAttribute = 0x10;

/// Owns a zip_error_t for the duration of one libzip call sequence.
struct ErrorHolder {
    zip_error_t error;
    ErrorHolder() { zip_error_init(&error); }
    ~ErrorHolder() { zip_error_fini(&error); }
    ErrorHolder(const ErrorHolder&) = delete;
    ErrorHolder& operator=(const ErrorHolder&) = delete;
    std::string text() { return zip_error_strerror(&error); }
};

} // namespace

struct ZipReader::Impl {
    zip_t* archive = nullptr;
    ~Impl() {
        if (archive) zip_discard(archive);
    }
};

ZipReader::ZipReader(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
ZipReader::~ZipReader() = default;

std::unique_ptr<ZipReader> ZipReader::open(std::string_view bytes) {
    auto attempt = [&](int flags, int& code, std::string& message) -> zip_t* {
        ErrorHolder e;
        zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &e.error);
        if (!source) throw ZipError(e.text());
        zip_t* archive = zip_open_from_source(source, flags, &e.error);
        if (!archive) {
            code = zip_error_code_zip(&e.error);
            message = e.text();
            zip_source_free(source);
        }
        return archive;
    };
    int code = 0;
    std::string message;
    zip_t* archive = attempt(ZIP_RDONLY | ZIP_CHECKCONS, code, message);
    // With ZIP_CHECKCONS libzip refuses repeated names outright; without it they open, so the
    // package rules can name the duplicate. Every other defect is still a failed open.
    if (!archive && code == ZIP_ER_EXISTS) archive = attempt(ZIP_RDONLY, code, message);
    if (!archive) throw ZipError(message);
    auto impl = std::make_unique<Impl>();
    impl->archive = archive;
    return std::unique_ptr<ZipReader>(new ZipReader(std::move(impl)));
}

uint64_t ZipReader::entryCount() const {
    zip_int64_t n = zip_get_num_entries(m_impl->archive, 0);
    return n < 0 ? 0 : static_cast<uint64_t>(n);
}

ZipEntryInfo ZipReader::entry(uint64_t index) const {
    zip_t* za = m_impl->archive;
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(za, index, ZIP_FL_ENC_RAW, &st) != 0) throw ZipError(zip_strerror(za));
    constexpr zip_uint64_t kNeeded = ZIP_STAT_NAME | ZIP_STAT_SIZE | ZIP_STAT_COMP_SIZE | ZIP_STAT_COMP_METHOD;
    if ((st.valid & kNeeded) != kNeeded) throw ZipError("incomplete central directory entry");
    ZipEntryInfo info;
    info.name = st.name;
    info.size = st.size;
    info.compressedSize = st.comp_size;
    info.compressionMethod = st.comp_method;
    info.compressionSupported = st.comp_method == ZIP_CM_STORE || st.comp_method == ZIP_CM_DEFLATE;
    info.encrypted = (st.valid & ZIP_STAT_ENCRYPTION_METHOD) && st.encryption_method != ZIP_EM_NONE;
    zip_uint8_t opsys = 0;
    zip_uint32_t attributes = 0;
    if (zip_file_get_external_attributes(za, index, 0, &opsys, &attributes) != 0) throw ZipError(zip_strerror(za));
    if (opsys == ZIP_OPSYS_UNIX) info.unixMode = attributes >> 16;
    info.dosDirectory = (attributes & kDosDirectoryAttribute) != 0;
    return info;
}

std::string ZipReader::read(uint64_t index, uint64_t declaredSize) const {
    zip_file_t* file = zip_fopen_index(m_impl->archive, index, 0);
    if (!file) throw ZipError(zip_strerror(m_impl->archive));
    std::string data(declaredSize, '\0');
    uint64_t done = 0;
    std::string problem;
    while (done < declaredSize) {
        zip_int64_t n = zip_fread(file, data.data() + done, declaredSize - done);
        if (n < 0) {
            problem = zip_file_strerror(file);
            break;
        }
        if (n == 0) {
            problem =
                "data ends after " + std::to_string(done) + " of " + std::to_string(declaredSize) + " declared bytes";
            break;
        }
        done += static_cast<uint64_t>(n);
    }
    if (problem.empty()) {
        // Reading past the end lets libzip verify the CRC-32 and detect surplus data.
        char extra = 0;
        zip_int64_t n = zip_fread(file, &extra, 1);
        if (n < 0)
            problem = zip_file_strerror(file);
        else if (n > 0)
            problem = "data is longer than the declared " + std::to_string(declaredSize) + " bytes";
    }
    zip_fclose(file);
    if (!problem.empty()) throw ZipError(problem);
    return data;
}

std::string writeZip(const std::vector<ZipInput>& entries) {
    ErrorHolder e;
    zip_source_t* output = zip_source_buffer_create(nullptr, 0, 0, &e.error);
    if (!output) throw ZipError(e.text());
    zip_source_keep(output); // survives zip_close so the result can be read back
    struct SourceRef {
        zip_source_t* source;
        ~SourceRef() { zip_source_free(source); }
    } outputRef{output};

    zip_t* za = zip_open_from_source(output, ZIP_TRUNCATE, &e.error);
    if (!za) throw ZipError(e.text());
    auto failWith = [&](std::string what) {
        std::string message = what + ": " + zip_strerror(za);
        zip_discard(za);
        throw ZipError(message);
    };
    for (const ZipInput& in : entries) {
        std::string name(in.name);
        zip_source_t* data = zip_source_buffer(za, in.bytes.data(), in.bytes.size(), 0);
        if (!data) failWith(name);
        zip_int64_t index = zip_file_add(za, name.c_str(), data, ZIP_FL_ENC_UTF_8);
        if (index < 0) {
            zip_source_free(data);
            failWith(name);
        }
        auto i = static_cast<zip_uint64_t>(index);
        if (zip_set_file_compression(za, i, ZIP_CM_DEFLATE, 9) != 0 ||
            zip_file_set_dostime(za, i, kDosTimeMidnight, kDosDate1980Jan1, 0) != 0 ||
            zip_file_set_external_attributes(za, i, 0, ZIP_OPSYS_UNIX, kUnixRegularFile0644 << 16) != 0)
            failWith(name);
    }
    if (zip_close(za) != 0) failWith("closing the archive");

    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_source_stat(output, &st) != 0 || !(st.valid & ZIP_STAT_SIZE) || zip_source_open(output) != 0)
        throw ZipError(zip_error_strerror(zip_source_error(output)));
    std::string bytes(st.size, '\0');
    zip_int64_t n = zip_source_read(output, bytes.data(), st.size);
    zip_source_close(output);
    if (n < 0 || static_cast<zip_uint64_t>(n) != st.size) throw ZipError("reading the finished archive back failed");
    return bytes;
}

} // namespace viscera::vcase::detail
