// aerie-keys: make, compare and rotate the link's mission key (docs/security.md, "Key files and
// fingerprints"). The key itself is never printed: only its fingerprint.
//   aerie-keys generate --out FILE [--force]
//   aerie-keys fingerprint FILE
//   aerie-keys rotate FILE [--force]
//   aerie-keys operator --out FILE [--force]      (FILE and FILE.pub: the operator's signing key)
// Exit status: 0 done, 1 an error (named on stderr), CLI11's code for a wrong option.
#include <CLI/CLI.hpp>

#include <iostream>
#include <stdexcept>

#include "common/seal/keys.hpp"
#include "common/seal/operator.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Make, compare and rotate the mission key that seals the air-ground link, and the operator's key "
               "that signs commands",
               "aerie-keys"};
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
  fp->add_option("file", file, "Mission key file, or an operator's FILE.pub")->required();
  bool operator_key = false;
  fp->add_flag("--operator", operator_key,
               "FILE is an operator key (its public key's fingerprint is printed; implied for FILE.pub)");

  auto* rot = app.add_subcommand("rotate", "Replace a key file by a new random key, keeping the old one as FILE.old "
                                           "(mode 0600); prints both fingerprints");
  rot->add_option("file", file, "Mission key file to rotate")->required();
  rot->add_flag("--force", force, "Replace an existing FILE.old (refused otherwise)");
  rot->footer("Copy the new key to the other half, then restart both halves; FILE.old lets you go back.");

  auto* op = app.add_subcommand("operator", "Write a new operator key: FILE (the Ed25519 seed, mode 0600, for the "
                                            "ground half's --operator-key) and FILE.pub (for the air half's "
                                            "--operator-pub); prints the public key's fingerprint");
  op->add_option("--out", out, "Operator key file to write (FILE.pub beside it)")->required();
  op->add_flag("--force", force, "Replace existing files (refused otherwise)");
  op->footer("One operator key per ground station that may command; a station without one only watches. "
             "Copy FILE.pub to the vehicle, never FILE.");

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
      const bool pub = file.size() > 4 && file.compare(file.size() - 4, 4, ".pub") == 0;
      if (pub) std::cout << OperatorPublicKey::load(file).fingerprint() << "\n";
      else if (operator_key) std::cout << OperatorKey::load(file).public_key().fingerprint() << "\n";
      else std::cout << fingerprint(load_key(file)) << "\n";
    } else if (*op) {
      const OperatorKey key = OperatorKey::generate();
      key.save(out, force);
      key.public_key().save(out + ".pub", force);
      std::cout << "wrote operator key " << out << " (mode 0600) and " << out << ".pub\npublic key fingerprint "
                << key.public_key().fingerprint() << "\n";
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
