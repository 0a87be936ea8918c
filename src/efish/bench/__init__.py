"""Speed and accuracy studies printed by ``efish bench ...``."""
