"""Views over traces and rulebooks for auditors: explanations, firing statistics."""
