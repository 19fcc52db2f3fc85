# OpenSSL libcrypto (sha256) -> OpenSSL::Crypto
find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)
