// aerie-keys: make, compare and rotate the link's mission key (docs/security.md, "Key files and
// fingerprints"). The key itself is never printed: only its fingerprint.
//   aerie-keys generate --out FILE [--force]
//   aerie-keys fingerprint FILE
//   aerie-keys rotate FILE [--force]
// Exit status: 0 done, 1 an error (named on stderr), CLI11's code for a wrong option.
#include <CLI/CLI.hpp>

#include <iostream>
#include <stdexcept>

#include "common/seal/keys.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Make, compare and rotate the mission key that seals the air-ground link", "aerie-keys"};
  app.require_subcommand(1);
  app.footer("A mission key file holds 32 random bytes with mode 0600; both link halves need the same file. "
             "Compare the fingerprints the halves show, never the keys.");
  std::string out, file;
  bool force = false;

  auto* gen = app.add_subcommand("generate", "Write a new random mission key (mode 0600) and print its fingerprint");
  gen->add_option("--out", out, "Key file to write")->required();
  gen->add_flag("--force", force, "Replace an existing key file (refused otherwise)");

  auto* fp = app.add_subcommand("fingerprint", "Print a key file's fingerprint (the first 8 bytes of its BLAKE2b "
                                               "hash), to compare the two halves' keys");
  fp->add_option("file", file, "Mission key file")->required();

  auto* rot = app.add_subcommand("rotate", "Replace a key file by a new random key, keeping the old one as FILE.old "
                                           "(mode 0600); prints both fingerprints");
  rot->add_option("file", file, "Mission key file to rotate")->required();
  rot->add_flag("--force", force, "Replace an existing FILE.old (refused otherwise)");
  rot->footer("Copy the new key to the other half, then restart both halves; FILE.old lets you go back.");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);  // prints the help or the error
  }
  try {
    using namespace aerie::seal;
    if (*gen) {
      const SecretKey key = SecretKey::generate();
      save_key(out, key, force);
      std::cout << "wrote mission key " << out << " (mode 0600)\nfingerprint " << fingerprint(key) << "\n";
    } else if (*fp) {
      std::cout << fingerprint(load_key(file)) << "\n";
    } else if (*rot) {
      const SecretKey old_key = load_key(file);
      const SecretKey new_key = SecretKey::generate();
      save_key(file + ".old", old_key, force);
      save_key(file, new_key, true);
      std::cout << "rotated mission key " << file << "\nold fingerprint " << fingerprint(old_key) << " (kept in "
                << file << ".old)\nnew fingerprint " << fingerprint(new_key) << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "aerie-keys: " << e.what() << "\n";
    return 1;
  }
}
